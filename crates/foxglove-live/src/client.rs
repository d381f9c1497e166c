//! One client: the handshake, its queue (filled by the publisher, capped in bytes) and its thread's
//! loop, which reads the client's requests without blocking and writes what is queued.

use std::collections::VecDeque;
use std::io::ErrorKind;
use std::net::TcpStream;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use tungstenite::handshake::server::{ErrorResponse, Request, Response};
use tungstenite::http::{HeaderValue, StatusCode, header::SEC_WEBSOCKET_PROTOCOL};
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Bytes, HandshakeError, Message, WebSocket};

use crate::protocol::{
    ClientOp, SUBPROTOCOL_SDK, SUBPROTOCOL_WS, ServerInfo, Status, choose_subprotocol,
    frame_message_data, frame_time, parse_client_op,
};
use crate::{Shared, lock};

/// The longest a client may take to send its upgrade request.
const HANDSHAKE_TIMEOUT: Duration = Duration::from_secs(5);
/// How often a handshake in progress looks whether the server stops.
const HANDSHAKE_POLL: Duration = Duration::from_millis(50);
/// How long an idle client thread sleeps before looking at its socket for requests again.
const IDLE_POLL: Duration = Duration::from_millis(10);
/// Messages written between two looks at the client's requests.
const BATCH: usize = 64;
/// After sending *Close*, how long to wait for the client's *Close*.
const CLOSE_WAIT: Duration = Duration::from_millis(500);

/// A message waiting in a client's queue.
enum Outgoing {
    /// *Message Data* for one subscription.
    Data {
        subscription_id: u32,
        t_ns: u64,
        payload: Arc<[u8]>,
    },
    /// *Time*.
    Time(u64),
    /// A JSON text message (*Advertise*, *Status*).
    Text(Arc<str>),
}

impl Outgoing {
    fn bytes(&self) -> usize {
        match self {
            Outgoing::Data { payload, .. } => payload.len(),
            Outgoing::Time(_) => 8,
            Outgoing::Text(_) => 0,
        }
    }
}

#[derive(Default)]
struct ClientState {
    /// (subscription id, channel index).
    subscriptions: Vec<(u32, usize)>,
    queue: VecDeque<Outgoing>,
    /// Payload bytes in `queue` (texts are not counted: they are few and small).
    queued_bytes: usize,
    /// The thread has ended; nothing more is queued.
    gone: bool,
}

/// The publisher's side of one client.
pub(crate) struct Client {
    state: Mutex<ClientState>,
    ready: Condvar,
}

impl Client {
    /// Queues a text message (never dropped).
    pub fn push_text(&self, text: Arc<str>) {
        let mut st = lock(&self.state);
        if !st.gone {
            st.queue.push_back(Outgoing::Text(text));
            drop(st);
            self.ready.notify_one();
        }
    }

    /// Queues `payload` for each of this client's subscriptions of channel `index`, or drops and
    /// counts it where the queue's byte budget would be exceeded.
    pub fn offer_data(&self, shared: &Shared, index: usize, t_ns: u64, payload: &Arc<[u8]>) {
        let mut guard = lock(&self.state);
        let st = &mut *guard;
        if st.gone {
            return;
        }
        let mut queued = false;
        for &(subscription_id, _) in st.subscriptions.iter().filter(|s| s.1 == index) {
            if st.queued_bytes + payload.len() > shared.config.queue_budget_bytes {
                shared.dropped.fetch_add(1, Ordering::Relaxed);
                continue;
            }
            st.queued_bytes += payload.len();
            st.queue.push_back(Outgoing::Data {
                subscription_id,
                t_ns,
                payload: Arc::clone(payload),
            });
            queued = true;
        }
        drop(guard);
        if queued {
            self.ready.notify_one();
        }
    }

    /// Queues a *Time* message unless the queue is full (then it is left out, uncounted).
    pub fn offer_time(&self, shared: &Shared, t_ns: u64) {
        let mut st = lock(&self.state);
        if st.gone || st.queued_bytes + 8 > shared.config.queue_budget_bytes {
            return;
        }
        st.queued_bytes += 8;
        st.queue.push_back(Outgoing::Time(t_ns));
        drop(st);
        self.ready.notify_one();
    }

    /// Wakes the client's thread (at shutdown).
    pub fn wake(&self) {
        self.ready.notify_all();
    }

    /// The next queued message, waiting up to `wait` for one.
    fn next(&self, wait: Duration) -> Option<Outgoing> {
        let mut st = lock(&self.state);
        if st.queue.is_empty() && !wait.is_zero() {
            st = self
                .ready
                .wait_timeout(st, wait)
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .0;
        }
        let item = st.queue.pop_front()?;
        st.queued_bytes -= item.bytes();
        Some(item)
    }
}

/// The handshake's subprotocol choice (see [`choose_subprotocol`]); no acceptable offer is an
/// HTTP 400 naming the two we speak.
#[allow(clippy::result_large_err)] // tungstenite's callback signature
fn pick_subprotocol(request: &Request, mut response: Response) -> Result<Response, ErrorResponse> {
    let offered = request
        .headers()
        .get_all(SEC_WEBSOCKET_PROTOCOL)
        .iter()
        .filter_map(|v| v.to_str().ok());
    match choose_subprotocol(offered) {
        Some(p) => {
            response
                .headers_mut()
                .insert(SEC_WEBSOCKET_PROTOCOL, HeaderValue::from_static(p));
            Ok(response)
        }
        None => {
            let mut refused = ErrorResponse::new(Some(format!(
                "expected the subprotocol {SUBPROTOCOL_SDK} or {SUBPROTOCOL_WS}"
            )));
            *refused.status_mut() = StatusCode::BAD_REQUEST;
            Err(refused)
        }
    }
}

/// Serves one connection until it ends or the server stops.
pub(crate) fn serve(shared: &Arc<Shared>, stream: TcpStream) {
    let setup = stream
        .set_nonblocking(false)
        .and_then(|()| stream.set_nodelay(true))
        .and_then(|()| stream.set_read_timeout(Some(HANDSHAKE_POLL)))
        .and_then(|()| stream.set_write_timeout(Some(shared.config.write_timeout)));
    if setup.is_err() {
        return;
    }
    // write_buffer_size 0: every message goes to the socket at once; the buffer only fills behind
    // a socket that does not drain, up to the budget.
    let ws_config = WebSocketConfig::default()
        .write_buffer_size(0)
        .max_write_buffer_size(shared.config.write_buffer_bytes);
    let give_up = Instant::now() + HANDSHAKE_TIMEOUT;
    let mut handshake =
        tungstenite::accept_hdr_with_config(stream, pick_subprotocol, Some(ws_config));
    let mut ws = loop {
        match handshake {
            Ok(ws) => break ws,
            Err(HandshakeError::Interrupted(mid))
                if Instant::now() < give_up && !shared.stop.load(Ordering::SeqCst) =>
            {
                handshake = mid.handshake();
            }
            Err(_) => return,
        }
    };
    let client = Arc::new(Client {
        state: Mutex::new(ClientState::default()),
        ready: Condvar::new(),
    });
    register(shared, &client);
    let mut link = Link {
        shared,
        client: &client,
        frame: Vec::new(),
    };
    if link.run(&mut ws) {
        let _ = ws.close(None);
        let _ = ws.flush();
        let _ = ws.get_mut().set_read_timeout(Some(CLOSE_WAIT));
        let until = Instant::now() + CLOSE_WAIT;
        while Instant::now() < until {
            match ws.read() {
                Ok(_) => {}
                Err(tungstenite::Error::Io(e)) if e.kind() == ErrorKind::WouldBlock => {}
                Err(_) => break,
            }
        }
    }
    unregister(shared, &client);
}

/// Queues *Server Info* and the *Advertise* of every channel, and makes the client visible to the
/// publisher, under the channel lock (so that a channel added meanwhile is advertised once).
fn register(shared: &Shared, client: &Arc<Client>) {
    let channels = lock(&shared.channels);
    let info = serde_json::to_string(&ServerInfo {
        op: "serverInfo",
        name: &shared.name,
        capabilities: ["time"],
        supported_encodings: [],
        metadata: serde_json::Map::new(),
        session_id: &shared.session_id,
    })
    .unwrap_or_default();
    client.push_text(info.into());
    if !channels.is_empty() {
        client.push_text(Shared::advertise_text(&channels).into());
    }
    lock(&shared.clients).push(Arc::clone(client));
    shared.clients_total.fetch_add(1, Ordering::Relaxed);
}

/// Removes the client and its subscriptions.
fn unregister(shared: &Shared, client: &Arc<Client>) {
    lock(&shared.clients).retain(|c| !Arc::ptr_eq(c, client));
    let mut st = lock(&client.state);
    st.gone = true;
    for (_, index) in st.subscriptions.drain(..) {
        shared.subscribers[index].fetch_sub(1, Ordering::Relaxed);
    }
    st.queue.clear();
    st.queued_bytes = 0;
}

/// The client thread's loop.
struct Link<'a> {
    shared: &'a Shared,
    client: &'a Client,
    /// The binary frame being written, reused.
    frame: Vec<u8>,
}

/// What became of a message written.
enum Written {
    /// Handed to the socket.
    Yes,
    /// Kept in tungstenite's buffer (or dropped and counted when that is full): the socket did
    /// not take it within the write timeout.
    Backlogged,
    /// The connection is gone.
    Gone,
}

fn would_block(e: &tungstenite::Error) -> bool {
    matches!(e, tungstenite::Error::Io(io) if matches!(io.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut))
}

impl Link<'_> {
    /// Runs until the client leaves (false) or the server stops (true: close the connection).
    ///
    /// A socket that did not take a write within the write timeout is *backlogged*: nothing more
    /// is written to it until a flush gets through, so its messages wait in the queue (where the
    /// byte budget drops and counts them) and each turn of the loop blocks at most one write
    /// timeout, so that requests and the shutdown are still seen.
    fn run(&mut self, ws: &mut WebSocket<TcpStream>) -> bool {
        let mut backlogged = false;
        loop {
            if !self.read_requests(ws) {
                return false;
            }
            let stopping = self.shared.stop.load(Ordering::SeqCst);
            if stopping {
                let deadline = (*lock(&self.shared.drain_deadline)).unwrap_or_else(Instant::now);
                if Instant::now() >= deadline {
                    return true;
                }
            }
            if backlogged {
                match ws.flush() {
                    Ok(()) => backlogged = false,
                    Err(e) if would_block(&e) => continue,
                    Err(_) => return false,
                }
            }
            let mut written = 0;
            let wait = if stopping { Duration::ZERO } else { IDLE_POLL };
            while written < BATCH {
                let Some(item) = self
                    .client
                    .next(if written == 0 { wait } else { Duration::ZERO })
                else {
                    break;
                };
                written += 1;
                match self.write(ws, item) {
                    Written::Yes => {}
                    Written::Backlogged => {
                        backlogged = true;
                        break;
                    }
                    Written::Gone => return false,
                }
            }
            if !backlogged {
                match ws.flush() {
                    Ok(()) => {
                        if stopping && written == 0 {
                            return true;
                        }
                    }
                    Err(e) if would_block(&e) => backlogged = true,
                    Err(_) => return false,
                }
            }
        }
    }

    /// Writes one message.
    fn write(&mut self, ws: &mut WebSocket<TcpStream>, item: Outgoing) -> Written {
        let (message, data) = match item {
            Outgoing::Data {
                subscription_id,
                t_ns,
                payload,
            } => {
                frame_message_data(&mut self.frame, subscription_id, t_ns, &payload);
                (Message::Binary(Bytes::copy_from_slice(&self.frame)), true)
            }
            Outgoing::Time(t_ns) => {
                frame_time(&mut self.frame, t_ns);
                (Message::Binary(Bytes::copy_from_slice(&self.frame)), false)
            }
            Outgoing::Text(text) => (Message::text(&*text), false),
        };
        let (counter, written) = match ws.write(message) {
            Ok(()) => (&self.shared.sent, Written::Yes),
            // Buffered: tungstenite writes it out on the next write or flush.
            Err(e) if would_block(&e) => (&self.shared.sent, Written::Backlogged),
            Err(tungstenite::Error::WriteBufferFull(_)) => {
                (&self.shared.dropped, Written::Backlogged)
            }
            Err(_) => return Written::Gone,
        };
        if data {
            counter.fetch_add(1, Ordering::Relaxed);
        }
        written
    }

    /// Reads and answers every request waiting on the socket, without blocking; false when the
    /// client left or broke the protocol.
    fn read_requests(&mut self, ws: &mut WebSocket<TcpStream>) -> bool {
        if ws.get_mut().set_nonblocking(true).is_err() {
            return false;
        }
        let alive = loop {
            match ws.read() {
                Ok(Message::Text(text)) => self.request(text.as_str()),
                Ok(Message::Close(_)) => break false,
                Ok(_) => {}
                Err(e) if would_block(&e) => break true,
                Err(_) => break false,
            }
        };
        alive && ws.get_mut().set_nonblocking(false).is_ok()
    }

    fn status(&self, level: u8, message: &str) {
        let text = serde_json::to_string(&Status {
            op: "status",
            level,
            message,
        })
        .unwrap_or_default();
        self.client.push_text(text.into());
    }

    /// Acts on one text request (*Subscribe*, *Unsubscribe*); answers a bad one with a *Status*
    /// warning.
    fn request(&mut self, text: &str) {
        match parse_client_op(text) {
            ClientOp::Subscribe(subscriptions) => {
                let channels = lock(&self.shared.channels).len();
                let mut accepted = 0;
                let mut refused = Vec::new();
                {
                    let mut st = lock(&self.client.state);
                    for s in subscriptions {
                        let index = s.channel_id as usize;
                        if index == 0 || index > channels {
                            refused.push(format!("channel {} is not advertised", s.channel_id));
                        } else if st.subscriptions.iter().any(|&(id, _)| id == s.id) {
                            refused.push(format!("subscription id {} is already used", s.id));
                        } else if st.subscriptions.iter().any(|&(_, i)| i == index - 1) {
                            refused.push(format!("channel {} is already subscribed", s.channel_id));
                        } else {
                            st.subscriptions.push((s.id, index - 1));
                            self.shared.subscribers[index - 1].fetch_add(1, Ordering::Relaxed);
                            accepted += 1;
                        }
                    }
                }
                for r in refused {
                    self.status(1, &format!("subscribe: {r}"));
                }
                if accepted > 0 {
                    *lock(&self.shared.subscriptions) += accepted;
                    self.shared.subscribed.notify_all();
                }
            }
            ClientOp::Unsubscribe(ids) => {
                let mut st = lock(&self.client.state);
                for id in ids {
                    if let Some(k) = st.subscriptions.iter().position(|&(s, _)| s == id) {
                        let (_, index) = st.subscriptions.swap_remove(k);
                        self.shared.subscribers[index].fetch_sub(1, Ordering::Relaxed);
                    }
                }
            }
            ClientOp::Ignored(_) => {}
            ClientOp::Malformed(why) => self.status(1, &format!("bad request: {why}")),
        }
    }
}
