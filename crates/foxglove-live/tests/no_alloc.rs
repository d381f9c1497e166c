//! The publisher's side costs no allocation when no client subscribed (the tracker's frame loop
//! with `--foxglove` and nobody watching), and one per message (the shared payload) when one did,
//! once the client's queue has grown.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::io::Read;
use std::net::TcpStream;
use std::time::{Duration, Instant};

use alloc_counter::allocations_in;
use foxglove_live::{LiveConfig, LiveServer};
use tungstenite::Message;
use tungstenite::client::IntoClientRequest;

#[global_allocator]
static ALLOC: alloc_counter::CountingAllocator = alloc_counter::CountingAllocator::new();

#[test]
fn publishing_without_a_subscriber_allocates_nothing_and_with_one_once_per_message() {
    let server = LiveServer::bind("127.0.0.1:0", "test", LiveConfig::default()).unwrap();
    let ch = server.add_channel("/a", "A", "{}").unwrap();
    let payload = vec![7u8; 100_000];
    let ((), n) = allocations_in(|| {
        for k in 0..1000 {
            if server.wants(ch) {
                unreachable!("nobody subscribed");
            }
            server.publish(ch, k, &payload);
            server.time(k);
        }
    });
    assert_eq!(n, 0, "allocations without a subscriber");

    let addr = server.local_addr();
    let stream = TcpStream::connect(addr).unwrap();
    let mut request = format!("ws://{addr}/").into_client_request().unwrap();
    request
        .headers_mut()
        .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
    let mut ws = tungstenite::client(request, stream).unwrap().0;
    ws.send(Message::text(
        r#"{"op":"subscribe","subscriptions":[{"id":1,"channelId":1}]}"#,
    ))
    .unwrap();
    let end = Instant::now() + Duration::from_secs(10);
    while !server.wants(ch) {
        assert!(Instant::now() < end, "no subscription");
        std::thread::sleep(Duration::from_millis(1));
    }
    // A reader drains the socket so that the queue stays short.
    let mut raw = ws.get_ref().try_clone().unwrap();
    let reader = std::thread::spawn(move || {
        let mut buf = vec![0u8; 1 << 16];
        while raw.read(&mut buf).is_ok_and(|n| n > 0) {}
    });
    // Warm-up: a burst grows the client's queue past any lag of the reader below, then steady.
    for k in 0..256 {
        server.publish(ch, k, &payload);
    }
    for k in 0..100 {
        server.publish(ch, k, &payload);
        std::thread::sleep(Duration::from_millis(1));
    }
    let messages = 200;
    let ((), n) = allocations_in(|| {
        for k in 0..messages {
            server.publish(ch, k, &payload);
            std::thread::sleep(Duration::from_millis(1));
        }
    });
    assert_eq!(
        n, messages,
        "one allocation (the shared payload) per message"
    );
    drop(server);
    drop(ws);
    reader.join().unwrap();
}
