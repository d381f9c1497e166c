//! A minimal live server of Foxglove's WebSocket protocol (foxglove/ws-protocol `docs/spec.md`;
//! what is spoken is in [`protocol`]) over sync `tungstenite`: no async runtime, no TLS.
//!
//! The publisher (the tracker's or the replay's thread) never waits for a client. [`LiveServer::
//! publish`] costs one atomic load when no client subscribed the channel; otherwise it copies the
//! payload once into an `Arc<[u8]>` and appends a reference to the queue of each subscribed client.
//! Each client has its own thread that frames the queued messages and writes them to its socket,
//! and reads its *Subscribe* and *Unsubscribe* requests. A client's queue is capped in bytes
//! ([`LiveConfig::queue_budget_bytes`]): a message that does not fit is dropped and counted, as is
//! one that does not fit tungstenite's write buffer ([`LiveConfig::write_buffer_bytes`]) behind a
//! socket that stopped draining. A stalled client therefore holds at most its budget plus its
//! write buffer, and the publisher goes on at its own pace.
//!
//! Threads: one accepting connections (polling a non-blocking listener, so that
//! [`LiveServer::shutdown`] can stop it), one per client. Shutdown lets each client's thread send
//! what is queued for a bounded time ([`LiveConfig::drain_timeout`]), then sends *Close*.

pub mod protocol;

mod client;

use std::net::{SocketAddr, TcpListener, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use protocol::{Advertise, AdvertisedChannel};
use serde::Serialize;

/// The most channels one server advertises.
pub const MAX_CHANNELS: usize = 64;

/// The one error of this crate.
#[derive(Debug, thiserror::Error)]
pub enum LiveError {
    /// Another process listens on the address.
    #[error("{addr}: address already in use")]
    AddrInUse {
        /// The address asked for.
        addr: String,
    },
    /// The address could not be listened on (other than being in use).
    #[error("cannot listen on {addr}")]
    Bind {
        /// The address asked for.
        addr: String,
        /// The socket's error.
        #[source]
        source: std::io::Error,
    },
    /// The address is not `host:port`, or the host does not resolve.
    #[error("{addr}: not a host:port address")]
    Address {
        /// The address given.
        addr: String,
        /// The resolver's error.
        #[source]
        source: std::io::Error,
    },
    /// [`MAX_CHANNELS`] channels were already added.
    #[error("channel {topic}: a server advertises at most {max} channels")]
    TooManyChannels {
        /// The topic of the channel refused.
        topic: String,
        /// [`MAX_CHANNELS`].
        max: usize,
    },
    /// A thread could not be started.
    #[error("cannot start the server's thread")]
    Thread(#[source] std::io::Error),
}

/// The server's limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LiveConfig {
    /// Bytes of message payload queued for one client before further messages to it are
    /// dropped and counted (default 64 MiB: a 320×240 grey clip of several hundred frames fits).
    pub queue_budget_bytes: usize,
    /// Bytes tungstenite may buffer for one client behind a socket that does not drain, beyond
    /// which a message is dropped and counted (default 4 MiB). A single message larger than this
    /// is never sent (it is counted as dropped).
    pub write_buffer_bytes: usize,
    /// At shutdown, the longest time each client is given to receive what is queued for it.
    pub drain_timeout: Duration,
    /// A socket write to a client that blocks longer than this returns (the message stays in the
    /// write buffer), so that the client's thread still reads requests and sees a shutdown.
    pub write_timeout: Duration,
}

impl Default for LiveConfig {
    fn default() -> Self {
        Self {
            queue_budget_bytes: 64 << 20,
            write_buffer_bytes: 4 << 20,
            drain_timeout: Duration::from_secs(2),
            write_timeout: Duration::from_millis(200),
        }
    }
}

/// A channel of a [`LiveServer`] (its advertised id is `index + 1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChannelId(usize);

impl ChannelId {
    /// The id clients see in *Advertise* and send back in *Subscribe*.
    pub fn wire_id(self) -> u32 {
        self.0 as u32 + 1
    }
}

/// What the server did, for a run's summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct LiveStats {
    /// Clients that completed the handshake since the server started.
    pub clients: u64,
    /// *Message Data* frames handed to clients' sockets.
    pub sent: u64,
    /// *Message Data* frames dropped because a client could not keep up.
    pub dropped: u64,
}

/// State shared by the server handle, the accept thread and the client threads.
pub(crate) struct Shared {
    pub name: String,
    pub session_id: String,
    pub config: LiveConfig,
    /// Advertised channels (lock order: `channels` before `clients`).
    pub channels: Mutex<Vec<AdvertisedChannel>>,
    /// Subscriptions per channel index, over all clients.
    pub subscribers: [AtomicU32; MAX_CHANNELS],
    pub clients: Mutex<Vec<Arc<client::Client>>>,
    /// Subscribe requests accepted so far (for [`LiveServer::wait_subscribed`]).
    pub subscriptions: Mutex<u64>,
    pub subscribed: Condvar,
    pub stop: AtomicBool,
    /// Set with `stop`: until when clients may go on sending what is queued.
    pub drain_deadline: Mutex<Option<Instant>>,
    pub clients_total: AtomicU64,
    pub sent: AtomicU64,
    pub dropped: AtomicU64,
    pub threads: Mutex<Vec<JoinHandle<()>>>,
}

/// Locks `m`, also when another thread panicked holding it (the data stay consistent: every
/// critical section here only pushes, pops or counts).
pub(crate) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Shared {
    /// The *Advertise* text of `channels`.
    pub fn advertise_text(channels: &[AdvertisedChannel]) -> String {
        serde_json::to_string(&Advertise {
            op: "advertise",
            channels,
        })
        .unwrap_or_default()
    }
}

/// A running server. Dropping it shuts it down (without waiting for a drain).
pub struct LiveServer {
    shared: Arc<Shared>,
    local_addr: SocketAddr,
    accept: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for LiveServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveServer")
            .field("local_addr", &self.local_addr)
            .field("stats", &self.stats())
            .finish()
    }
}

impl LiveServer {
    /// Listens on `addr` (`host:port`; port 0 picks a free one, see [`Self::local_addr`]) as the
    /// server `name`, and starts accepting clients.
    ///
    /// # Errors
    /// [`LiveError::AddrInUse`] naming `addr`, [`LiveError::Bind`], [`LiveError::Address`],
    /// [`LiveError::Thread`].
    pub fn bind(addr: &str, name: &str, config: LiveConfig) -> Result<Self, LiveError> {
        let resolved: Vec<SocketAddr> = addr
            .to_socket_addrs()
            .map_err(|source| LiveError::Address {
                addr: addr.to_owned(),
                source,
            })?
            .collect();
        let listener = TcpListener::bind(&resolved[..]).map_err(|source| {
            if source.kind() == std::io::ErrorKind::AddrInUse {
                LiveError::AddrInUse {
                    addr: addr.to_owned(),
                }
            } else {
                LiveError::Bind {
                    addr: addr.to_owned(),
                    source,
                }
            }
        })?;
        let bind_err = |source| LiveError::Bind {
            addr: addr.to_owned(),
            source,
        };
        let local_addr = listener.local_addr().map_err(bind_err)?;
        listener.set_nonblocking(true).map_err(bind_err)?;
        let session_ms = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_millis());
        let shared = Arc::new(Shared {
            name: name.to_owned(),
            session_id: session_ms.to_string(),
            config,
            channels: Mutex::new(Vec::new()),
            subscribers: std::array::from_fn(|_| AtomicU32::new(0)),
            clients: Mutex::new(Vec::new()),
            subscriptions: Mutex::new(0),
            subscribed: Condvar::new(),
            stop: AtomicBool::new(false),
            drain_deadline: Mutex::new(None),
            clients_total: AtomicU64::new(0),
            sent: AtomicU64::new(0),
            dropped: AtomicU64::new(0),
            threads: Mutex::new(Vec::new()),
        });
        let accept_shared = Arc::clone(&shared);
        let accept = std::thread::Builder::new()
            .name("foxglove-accept".into())
            .spawn(move || accept_loop(&accept_shared, &listener))
            .map_err(LiveError::Thread)?;
        Ok(Self {
            shared,
            local_addr,
            accept: Some(accept),
        })
    }

    /// The address listened on (with the port picked when 0 was asked for).
    pub fn local_addr(&self) -> SocketAddr {
        self.local_addr
    }

    /// Adds a channel of JSON messages on `topic` following the JSON schema `schema_json` named
    /// `schema_name`, and advertises it to the clients already connected (later ones get it in
    /// their first *Advertise*).
    ///
    /// # Errors
    /// [`LiveError::TooManyChannels`].
    pub fn add_channel(
        &self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<ChannelId, LiveError> {
        let mut channels = lock(&self.shared.channels);
        if channels.len() == MAX_CHANNELS {
            return Err(LiveError::TooManyChannels {
                topic: topic.to_owned(),
                max: MAX_CHANNELS,
            });
        }
        let id = ChannelId(channels.len());
        let channel = AdvertisedChannel {
            id: id.wire_id(),
            topic: topic.to_owned(),
            encoding: "json",
            schema_name: schema_name.to_owned(),
            schema: schema_json.to_owned(),
            schema_encoding: "jsonschema",
        };
        let text: Arc<str> = Shared::advertise_text(std::slice::from_ref(&channel)).into();
        channels.push(channel);
        for c in lock(&self.shared.clients).iter() {
            c.push_text(Arc::clone(&text));
        }
        Ok(id)
    }

    /// Whether some client subscribed `channel` (one atomic load): when not, a caller can skip
    /// encoding its message.
    pub fn wants(&self, channel: ChannelId) -> bool {
        self.shared.subscribers[channel.0].load(Ordering::Relaxed) > 0
    }

    /// Sends `payload` on `channel` with the receive timestamp `t_ns` to every client that
    /// subscribed it; never waits for a client (see the crate doc).
    pub fn publish(&self, channel: ChannelId, t_ns: u64, payload: &[u8]) {
        if !self.wants(channel) {
            return;
        }
        let payload: Arc<[u8]> = Arc::from(payload);
        for c in lock(&self.shared.clients).iter() {
            c.offer_data(&self.shared, channel.0, t_ns, &payload);
        }
    }

    /// Sends a *Time* message (`t_ns`) to every client: the app's clock follows the data.
    pub fn time(&self, t_ns: u64) {
        for c in lock(&self.shared.clients).iter() {
            c.offer_time(&self.shared, t_ns);
        }
    }

    /// Waits up to `timeout` for a client to subscribe to a channel; true when one has (also
    /// before this call).
    pub fn wait_subscribed(&self, timeout: Duration) -> bool {
        let guard = lock(&self.shared.subscriptions);
        let (guard, _) = self
            .shared
            .subscribed
            .wait_timeout_while(guard, timeout, |n| *n == 0)
            .unwrap_or_else(PoisonError::into_inner);
        *guard > 0
    }

    /// Clients connected now.
    pub fn connected(&self) -> usize {
        lock(&self.shared.clients).len()
    }

    /// The counters so far.
    pub fn stats(&self) -> LiveStats {
        LiveStats {
            clients: self.shared.clients_total.load(Ordering::Relaxed),
            sent: self.shared.sent.load(Ordering::Relaxed),
            dropped: self.shared.dropped.load(Ordering::Relaxed),
        }
    }

    /// Stops accepting, gives each client up to [`LiveConfig::drain_timeout`] to receive what is
    /// queued for it, closes the connections and joins the threads; returns the final counters.
    pub fn shutdown(mut self) -> LiveStats {
        self.stop_and_join(Instant::now() + self.shared.config.drain_timeout);
        self.stats()
    }

    fn stop_and_join(&mut self, drain_deadline: Instant) {
        *lock(&self.shared.drain_deadline) = Some(drain_deadline);
        self.shared.stop.store(true, Ordering::SeqCst);
        for c in lock(&self.shared.clients).iter() {
            c.wake();
        }
        if let Some(accept) = self.accept.take() {
            let _ = accept.join();
        }
        let threads = std::mem::take(&mut *lock(&self.shared.threads));
        for t in threads {
            let _ = t.join();
        }
    }
}

impl Drop for LiveServer {
    fn drop(&mut self) {
        if self.accept.is_some() {
            self.stop_and_join(Instant::now());
        }
    }
}

/// Accepts connections until the server stops; each client gets its own thread (the handshake
/// included, so that a slow client does not hold up the others).
fn accept_loop(shared: &Arc<Shared>, listener: &TcpListener) {
    const POLL: Duration = Duration::from_millis(10);
    while !shared.stop.load(Ordering::SeqCst) {
        match listener.accept() {
            Ok((stream, _)) => {
                let client_shared = Arc::clone(shared);
                let spawned = std::thread::Builder::new()
                    .name("foxglove-client".into())
                    .spawn(move || client::serve(&client_shared, stream));
                if let Ok(handle) = spawned {
                    let mut threads = lock(&shared.threads);
                    threads.retain(|t| !t.is_finished());
                    threads.push(handle);
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => std::thread::sleep(POLL),
            Err(_) => std::thread::sleep(POLL),
        }
    }
}
