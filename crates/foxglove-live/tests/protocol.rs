//! The server over loopback (port 0) with tungstenite clients and raw TCP sockets: the handshake's
//! subprotocols, *Server Info* and *Advertise*, subscriptions and the binary framing, drops behind a
//! stalled client, the port in use, `wait_subscribed` and the shutdown.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use foxglove_live::{LiveConfig, LiveError, LiveServer};
use serde_json::Value;
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message, WebSocket};

const SCHEMA: &str = r#"{"type":"object"}"#;

fn server() -> LiveServer {
    LiveServer::bind("127.0.0.1:0", "test", LiveConfig::default()).unwrap()
}

/// A client offering `protocols`; the subprotocol the server chose.
fn try_connect(
    server: &LiveServer,
    protocols: &str,
) -> Result<(WebSocket<TcpStream>, String), tungstenite::Error> {
    let addr = server.local_addr();
    let stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let mut request = format!("ws://{addr}/").into_client_request().unwrap();
    request
        .headers_mut()
        .insert("Sec-WebSocket-Protocol", protocols.parse().unwrap());
    let (ws, response) = tungstenite::client(request, stream).map_err(|e| match e {
        tungstenite::HandshakeError::Failure(e) => e,
        tungstenite::HandshakeError::Interrupted(_) => panic!("interrupted handshake"),
    })?;
    let chosen = response
        .headers()
        .get("Sec-WebSocket-Protocol")
        .map(|v| v.to_str().unwrap().to_owned())
        .unwrap_or_default();
    Ok((ws, chosen))
}

fn connect(server: &LiveServer) -> WebSocket<TcpStream> {
    try_connect(server, "foxglove.websocket.v1").unwrap().0
}

fn read_json(ws: &mut WebSocket<TcpStream>) -> Value {
    loop {
        match ws.read().unwrap() {
            Message::Text(t) => return serde_json::from_str(t.as_str()).unwrap(),
            Message::Ping(_) | Message::Pong(_) => {}
            other => panic!("expected a text message, got {other:?}"),
        }
    }
}

fn read_binary(ws: &mut WebSocket<TcpStream>) -> Vec<u8> {
    loop {
        match ws.read().unwrap() {
            Message::Binary(b) => return b.to_vec(),
            Message::Text(_) | Message::Ping(_) | Message::Pong(_) => {}
            other => panic!("expected a binary message, got {other:?}"),
        }
    }
}

fn subscribe(ws: &mut WebSocket<TcpStream>, id: u32, channel_id: u32) {
    let op =
        format!(r#"{{"op":"subscribe","subscriptions":[{{"id":{id},"channelId":{channel_id}}}]}}"#);
    ws.send(Message::text(op)).unwrap();
}

/// Waits until `cond` holds (a subscription reaching the server is asynchronous).
fn until(what: &str, cond: impl Fn() -> bool) {
    let end = Instant::now() + Duration::from_secs(10);
    while !cond() {
        assert!(Instant::now() < end, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn both_subprotocols_are_accepted_and_an_unknown_one_refused() {
    let server = server();
    let (_ws, chosen) = try_connect(&server, "foxglove.websocket.v1").unwrap();
    assert_eq!(chosen, "foxglove.websocket.v1");
    let (_ws, chosen) = try_connect(&server, "foxglove.websocket.v1, foxglove.sdk.v1").unwrap();
    assert_eq!(chosen, "foxglove.sdk.v1");
    match try_connect(&server, "something.else") {
        Err(tungstenite::Error::Http(response)) => assert_eq!(response.status(), 400),
        other => panic!("expected HTTP 400, got {:?}", other.map(|r| r.1)),
    }
}

#[test]
fn server_info_then_advertise_and_late_channels_are_advertised() {
    let server = server();
    let lanes = server
        .add_channel("/lanes", "ita_nav.LaneFrame", SCHEMA)
        .unwrap();
    let mut early = connect(&server);
    let info = read_json(&mut early);
    assert_eq!(info["op"], "serverInfo");
    assert_eq!(info["name"], "test");
    assert_eq!(info["capabilities"], serde_json::json!(["time"]));
    let adv = read_json(&mut early);
    assert_eq!(adv["op"], "advertise");
    assert_eq!(adv["channels"][0]["id"], lanes.wire_id());
    assert_eq!(adv["channels"][0]["topic"], "/lanes");
    assert_eq!(adv["channels"][0]["encoding"], "json");
    assert_eq!(adv["channels"][0]["schemaName"], "ita_nav.LaneFrame");
    assert_eq!(adv["channels"][0]["schema"], SCHEMA);
    assert_eq!(adv["channels"][0]["schemaEncoding"], "jsonschema");
    until("the client to register", || server.connected() == 1);
    let image = server
        .add_channel("/camera/image", "foxglove.RawImage", SCHEMA)
        .unwrap();
    let adv = read_json(&mut early);
    assert_eq!(adv["channels"].as_array().unwrap().len(), 1);
    assert_eq!(adv["channels"][0]["id"], image.wire_id());
    let mut late = connect(&server);
    assert_eq!(read_json(&mut late)["op"], "serverInfo");
    let adv = read_json(&mut late);
    let topics: Vec<&str> = adv["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["topic"].as_str().unwrap())
        .collect();
    assert_eq!(topics, ["/lanes", "/camera/image"]);
}

#[test]
fn subscribed_messages_are_framed_little_endian_and_stop_after_unsubscribe() {
    let server = server();
    let a = server.add_channel("/a", "A", SCHEMA).unwrap();
    let b = server.add_channel("/b", "B", SCHEMA).unwrap();
    let mut ws = connect(&server);
    subscribe(&mut ws, 0x0102_0304, b.wire_id());
    until("the subscription", || server.wants(b));
    assert!(!server.wants(a));
    server.publish(a, 1, b"not subscribed");
    server.publish(b, 0x1122_3344_5566_7788, br#"{"x":1}"#);
    let mut expected = vec![0x01, 0x04, 0x03, 0x02, 0x01];
    expected.extend_from_slice(&0x1122_3344_5566_7788_u64.to_le_bytes());
    expected.extend_from_slice(br#"{"x":1}"#);
    assert_eq!(read_binary(&mut ws), expected);
    server.time(258);
    assert_eq!(read_binary(&mut ws), [0x02, 2, 1, 0, 0, 0, 0, 0, 0]);
    ws.send(Message::text(
        r#"{"op":"unsubscribe","subscriptionIds":[16909060]}"#,
    ))
    .unwrap();
    until("the unsubscription", || !server.wants(b));
    assert_eq!(server.stats().sent, 1);
}

#[test]
fn a_bad_subscription_gets_a_status_warning_and_the_connection_stays() {
    let server = server();
    let a = server.add_channel("/a", "A", SCHEMA).unwrap();
    let mut ws = connect(&server);
    read_json(&mut ws);
    read_json(&mut ws);
    subscribe(&mut ws, 1, 99);
    let status = read_json(&mut ws);
    assert_eq!(status["op"], "status");
    assert_eq!(status["level"], 1);
    assert!(status["message"].as_str().unwrap().contains("99"));
    ws.send(Message::text("{not json")).unwrap();
    assert_eq!(read_json(&mut ws)["op"], "status");
    subscribe(&mut ws, 1, a.wire_id());
    until("the subscription", || server.wants(a));
}

#[test]
fn a_stalled_client_drops_counted_and_never_blocks_the_publisher() {
    let config = LiveConfig {
        queue_budget_bytes: 64 << 10,
        write_buffer_bytes: 64 << 10,
        ..LiveConfig::default()
    };
    let server = LiveServer::bind("127.0.0.1:0", "test", config).unwrap();
    let ch = server.add_channel("/big", "B", SCHEMA).unwrap();
    // A client that subscribes and then never reads again.
    let mut stalled = connect(&server);
    subscribe(&mut stalled, 1, ch.wire_id());
    until("the subscription", || server.wants(ch));
    let payload = vec![b'x'; 10_000];
    // 20 000 messages of 10 kB (200 MB) against a 64 kB budget: the publisher returns, the
    // queue stays bounded and the excess is counted.
    for k in 0..20_000u64 {
        server.publish(ch, k, &payload);
    }
    let stats = server.stats();
    assert!(stats.dropped > 10_000, "{stats:?}");
    assert!(stats.sent + stats.dropped <= 20_000, "{stats:?}");
    let end = server.shutdown();
    assert_eq!(end.clients, 1);
    drop(stalled);
}

#[test]
fn a_port_in_use_is_an_error_naming_the_address() {
    let first = server();
    let addr = first.local_addr().to_string();
    match LiveServer::bind(&addr, "second", LiveConfig::default()) {
        Err(e @ LiveError::AddrInUse { .. }) => {
            assert_eq!(e.to_string(), format!("{addr}: address already in use"));
        }
        other => panic!("expected AddrInUse, got {other:?}"),
    }
    assert!(matches!(
        LiveServer::bind("no port here", "x", LiveConfig::default()),
        Err(LiveError::Address { .. })
    ));
}

#[test]
fn wait_subscribed_returns_once_a_client_subscribes() {
    let server = server();
    let ch = server.add_channel("/a", "A", SCHEMA).unwrap();
    assert!(!server.wait_subscribed(Duration::from_millis(20)));
    let mut ws = connect(&server);
    assert!(!server.wait_subscribed(Duration::from_millis(20)));
    subscribe(&mut ws, 5, ch.wire_id());
    assert!(server.wait_subscribed(Duration::from_secs(10)));
}

#[test]
fn shutdown_delivers_what_is_queued_then_closes() {
    let server = server();
    let ch = server.add_channel("/a", "A", SCHEMA).unwrap();
    let mut ws = connect(&server);
    subscribe(&mut ws, 1, ch.wire_id());
    until("the subscription", || server.wants(ch));
    for k in 0..500u64 {
        server.publish(ch, k, format!("{{\"k\":{k}}}").as_bytes());
    }
    let reader = std::thread::spawn(move || {
        let mut received = Vec::new();
        loop {
            match ws.read() {
                Ok(Message::Binary(b)) => {
                    received.push(u64::from_le_bytes(b[5..13].try_into().unwrap()))
                }
                Ok(Message::Close(_)) => {}
                Ok(_) => {}
                Err(tungstenite::Error::ConnectionClosed) => return (received, true),
                Err(_) => return (received, false),
            }
        }
    });
    let stats = server.shutdown();
    let (received, closed_cleanly) = reader.join().unwrap();
    assert_eq!(received, (0..500).collect::<Vec<_>>());
    assert!(closed_cleanly, "no close handshake");
    assert_eq!(stats.sent, 500);
    assert_eq!(stats.dropped, 0);
}

#[test]
fn a_raw_socket_that_never_upgrades_does_not_hold_up_shutdown() {
    let server = server();
    let mut raw = TcpStream::connect(server.local_addr()).unwrap();
    raw.write_all(b"GET / HTTP/1.1\r\n").unwrap();
    // Shutdown returns (a handshake in progress looks at the stop flag) and counted no client.
    let stats = server.shutdown();
    assert_eq!(stats.clients, 0);
    let mut rest = Vec::new();
    let _ = raw.read_to_end(&mut rest);
}
