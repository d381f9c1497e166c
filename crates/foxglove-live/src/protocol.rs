//! The messages of Foxglove's WebSocket protocol (foxglove/ws-protocol, `docs/spec.md`) that this
//! server speaks, as JSON text or binary frames.
//!
//! - *Handshake*: the client lists the subprotocols it supports in `Sec-WebSocket-Protocol`; the
//!   server selects one. We accept [`SUBPROTOCOL_SDK`] (`foxglove.sdk.v1`, today's Foxglove app
//!   and SDK) and [`SUBPROTOCOL_WS`] (`foxglove.websocket.v1`, the spec's name, older apps and
//!   Lichtblick), preferring the first; the wire format of both is the same. Any other offer is
//!   refused with HTTP 400.
//! - Server → client, text: *Server Info* (`serverInfo`, first, with the `time` capability),
//!   *Advertise* (`advertise`, the channels: topic, `json` message encoding, a JSON schema),
//!   *Status* (`status`, a warning about a bad client request).
//! - Client → server, text: *Subscribe* (`subscribe`, `subscriptions: [{id, channelId}]`, the
//!   subscription id chosen by the client) and *Unsubscribe* (`unsubscribe`, `subscriptionIds`).
//!   Other operations are ignored: we declare no `clientPublish`, `parameters` or `services`.
//! - Server → client, binary (all integers little-endian): *Message Data*, opcode `0x01`, `u32`
//!   subscription id, `u64` receive timestamp in nanoseconds, the payload; *Time*, opcode `0x02`,
//!   `u64` nanoseconds (the app's clock follows the data's own time, not the wall clock).

use serde::{Deserialize, Serialize};

/// The subprotocol of the current Foxglove app and SDK.
pub const SUBPROTOCOL_SDK: &str = "foxglove.sdk.v1";
/// The subprotocol named in the ws-protocol spec (same wire format).
pub const SUBPROTOCOL_WS: &str = "foxglove.websocket.v1";
/// Opcode of a binary *Message Data* frame.
pub const OP_MESSAGE_DATA: u8 = 0x01;
/// Opcode of a binary *Time* frame.
pub const OP_TIME: u8 = 0x02;
/// Bytes of a *Message Data* frame before its payload: opcode, subscription id, timestamp.
pub const MESSAGE_DATA_HEADER_BYTES: usize = 1 + 4 + 8;

/// The subprotocol to answer with, among the `Sec-WebSocket-Protocol` header values `offered`
/// (each a comma-separated list): [`SUBPROTOCOL_SDK`] if offered, else [`SUBPROTOCOL_WS`], else
/// none.
pub fn choose_subprotocol<'a>(offered: impl IntoIterator<Item = &'a str>) -> Option<&'static str> {
    let mut ws = false;
    for name in offered
        .into_iter()
        .flat_map(|v| v.split(','))
        .map(str::trim)
    {
        if name == SUBPROTOCOL_SDK {
            return Some(SUBPROTOCOL_SDK);
        }
        ws |= name == SUBPROTOCOL_WS;
    }
    ws.then_some(SUBPROTOCOL_WS)
}

/// Appends a *Message Data* frame to `out` (cleared first): `0x01`, `subscription_id`, `t_ns`,
/// `payload`.
pub fn frame_message_data(out: &mut Vec<u8>, subscription_id: u32, t_ns: u64, payload: &[u8]) {
    out.clear();
    out.reserve(MESSAGE_DATA_HEADER_BYTES + payload.len());
    out.push(OP_MESSAGE_DATA);
    out.extend_from_slice(&subscription_id.to_le_bytes());
    out.extend_from_slice(&t_ns.to_le_bytes());
    out.extend_from_slice(payload);
}

/// Appends a *Time* frame to `out` (cleared first): `0x02`, `t_ns`.
pub fn frame_time(out: &mut Vec<u8>, t_ns: u64) {
    out.clear();
    out.push(OP_TIME);
    out.extend_from_slice(&t_ns.to_le_bytes());
}

/// *Server Info*.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
pub(crate) struct ServerInfo<'a> {
    pub op: &'static str,
    pub name: &'a str,
    pub capabilities: [&'static str; 1],
    pub supported_encodings: [&'static str; 0],
    pub metadata: serde_json::Map<String, serde_json::Value>,
    pub session_id: &'a str,
}

/// One channel of an *Advertise* message.
#[derive(Serialize, Clone, Debug)]
#[serde(rename_all = "camelCase")]
pub(crate) struct AdvertisedChannel {
    pub id: u32,
    pub topic: String,
    pub encoding: &'static str,
    pub schema_name: String,
    pub schema: String,
    pub schema_encoding: &'static str,
}

/// *Advertise*.
#[derive(Serialize)]
pub(crate) struct Advertise<'a> {
    pub op: &'static str,
    pub channels: &'a [AdvertisedChannel],
}

/// *Status* (level 0 info, 1 warning, 2 error).
#[derive(Serialize)]
pub(crate) struct Status<'a> {
    pub op: &'static str,
    pub level: u8,
    pub message: &'a str,
}

/// One subscription of a *Subscribe* message.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "camelCase")]
pub(crate) struct Subscription {
    pub id: u32,
    pub channel_id: u32,
}

/// The client operations we act on; anything else (other ops, bad JSON) is [`ClientOp::Other`].
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum ClientOp {
    Subscribe(Vec<Subscription>),
    Unsubscribe(Vec<u32>),
    /// A well-formed operation we do not serve (`op` is its name).
    Ignored(String),
    /// Not a JSON object with a known `op` and the fields it needs.
    Malformed(String),
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Envelope {
    op: String,
    #[serde(default)]
    subscriptions: Option<Vec<Subscription>>,
    #[serde(default)]
    subscription_ids: Option<Vec<u32>>,
}

/// Reads a client's text message.
pub(crate) fn parse_client_op(text: &str) -> ClientOp {
    let envelope: Envelope = match serde_json::from_str(text) {
        Ok(e) => e,
        Err(e) => return ClientOp::Malformed(e.to_string()),
    };
    match envelope.op.as_str() {
        "subscribe" => envelope.subscriptions.map_or_else(
            || ClientOp::Malformed("subscribe without subscriptions".into()),
            ClientOp::Subscribe,
        ),
        "unsubscribe" => envelope.subscription_ids.map_or_else(
            || ClientOp::Malformed("unsubscribe without subscriptionIds".into()),
            ClientOp::Unsubscribe,
        ),
        _ => ClientOp::Ignored(envelope.op),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sdk_subprotocol_is_preferred_and_the_spec_one_accepted() {
        assert_eq!(
            choose_subprotocol(["foxglove.websocket.v1, foxglove.sdk.v1"]),
            Some(SUBPROTOCOL_SDK)
        );
        assert_eq!(
            choose_subprotocol(["x", "foxglove.websocket.v1"]),
            Some(SUBPROTOCOL_WS)
        );
        assert_eq!(choose_subprotocol(["foxglove.sdk.v1.1"]), None);
        assert_eq!(choose_subprotocol([]), None);
    }

    #[test]
    fn message_data_is_opcode_le_subscription_le_time_payload() {
        let mut out = vec![9, 9];
        frame_message_data(&mut out, 0x0403_0201, 0x0c0b_0a09_0807_0605, b"xy");
        assert_eq!(out, [1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, b'x', b'y']);
        frame_time(&mut out, 258);
        assert_eq!(out, [2, 2, 1, 0, 0, 0, 0, 0, 0]);
    }

    #[test]
    fn client_ops_are_read_and_bad_ones_named() {
        assert_eq!(
            parse_client_op(r#"{"op":"subscribe","subscriptions":[{"id":7,"channelId":2}]}"#),
            ClientOp::Subscribe(vec![Subscription {
                id: 7,
                channel_id: 2
            }])
        );
        assert_eq!(
            parse_client_op(r#"{"op":"unsubscribe","subscriptionIds":[7,8]}"#),
            ClientOp::Unsubscribe(vec![7, 8])
        );
        assert_eq!(
            parse_client_op(r#"{"op":"getParameters","parameterNames":[]}"#),
            ClientOp::Ignored("getParameters".into())
        );
        assert!(matches!(
            parse_client_op(r#"{"op":"subscribe"}"#),
            ClientOp::Malformed(_)
        ));
        assert!(matches!(parse_client_op("[1,"), ClientOp::Malformed(_)));
        assert!(matches!(
            parse_client_op(r#"{"op":"subscribe","subscriptions":[{"id":-1,"channelId":2}]}"#),
            ClientOp::Malformed(_)
        ));
    }
}
