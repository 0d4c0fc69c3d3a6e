//! The SSH side: accepting connections within the limits, authentication, what a
//! session may ask for, one log line per connection, and shutting down.
//!
//! Each connection gets a `Conn` (`conn`), russh's handler.

use std::collections::HashMap;
use std::hash::{BuildHasher, RandomState};
use std::net::{IpAddr, SocketAddr};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

use russh::keys::PrivateKey;
use russh::server::Handle;
use russh::{Disconnect, MethodKind};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::oneshot;

use super::config::Startups;
use super::conn::{Conn, Log};
use super::keys::Authorized;
use super::session::{Request, Shared};

/// Authentication attempts per connection.
pub const MAX_AUTH_ATTEMPTS: usize = 6;
/// Connections being refused at once (with a message) before more are dropped
/// without one: a flood costs a key exchange each.
pub const MAX_REFUSING: usize = 64;

/// Who may watch, as the server checks it.
#[derive(Debug)]
pub enum Admit {
    Keys(Authorized),
    Public,
}

/// The limits a connection is admitted under.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Watchers (authenticated sessions) at once.
    pub max_clients: usize,
    /// Connections at once from one address, authenticated or not.
    pub max_per_address: usize,
    /// Connections not yet authenticated.
    pub startups: Startups,
    /// Time from connecting to being authenticated (as sshd's LoginGraceTime).
    pub login_grace: Duration,
}

/// Where a connection stands, for the counts it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Phase {
    /// Admitted, not yet authenticated: holds a place among the startups.
    Pending,
    /// Authenticated and given a watcher's place.
    Watching,
    /// Authenticated when every watcher's place was taken: told so, then closed.
    Full,
}

/// What became of a new connection.
enum Arrival {
    Admitted,
    /// Told why in the banner, then closed.
    Refused(String),
    /// Closed at once, past the startups limit.
    Dropped,
}

#[derive(Debug, Default)]
struct Counts {
    /// Admitted connections (any phase), by address.
    by_address: HashMap<IpAddr, usize>,
    pending: usize,
    watching: usize,
    /// Connections dropped since the last log line about them, and when it was.
    dropped: u64,
    dropped_said: Option<Instant>,
}

/// The server's state, shared by its connections.
#[derive(Debug)]
pub struct State {
    pub shared: Arc<Shared>,
    pub admit: Admit,
    pub limits: Limits,
    counts: Mutex<Counts>,
    refusing: Mutex<usize>,
    /// Running watchers, to end them on shutdown; and every connection's handle.
    pub(super) watchers: Mutex<HashMap<u64, std::sync::mpsc::SyncSender<crate::tui::Wake>>>,
    handles: Mutex<HashMap<u64, Handle>>,
    next_id: AtomicU64,
    /// Draws the random early drops.
    dice: RandomState,
}

impl State {
    #[must_use]
    pub fn new(shared: Arc<Shared>, admit: Admit, limits: Limits) -> Self {
        Self {
            shared,
            admit,
            limits,
            counts: Mutex::default(),
            refusing: Mutex::default(),
            watchers: Mutex::default(),
            handles: Mutex::default(),
            next_id: AtomicU64::new(0),
            dice: RandomState::new(),
        }
    }

    /// Admits, refuses or drops a new connection from `ip`.
    fn arrive(&self, ip: IpAddr, id: u64) -> Arrival {
        let mut c = lock(&self.counts);
        let here = c.by_address.get(&ip).copied().unwrap_or(0);
        if here >= self.limits.max_per_address {
            return Arrival::Refused(format!(
                "{here} connections from {ip} already, the most it takes"
            ));
        }
        if c.watching >= self.limits.max_clients {
            return Arrival::Refused(self.full_text(c.watching));
        }
        let roll = (self.dice.hash_one(id) % 100) as usize;
        if self.limits.startups.drops(c.pending, roll) {
            c.dropped += 1;
            let now = Instant::now();
            if c.dropped_said
                .is_none_or(|t| now - t >= Duration::from_secs(1))
            {
                eprintln!(
                    "{} dropped {} connection(s) past --max-startups ({} waiting to \
                     authenticate)",
                    utc(SystemTime::now()),
                    c.dropped,
                    c.pending
                );
                c.dropped = 0;
                c.dropped_said = Some(now);
            }
            return Arrival::Dropped;
        }
        c.pending += 1;
        *c.by_address.entry(ip).or_insert(0) += 1;
        Arrival::Admitted
    }

    /// A pending connection has authenticated: gives it a watcher's place if one is
    /// free, else says why not.
    pub(super) fn authenticated(&self, phase: &Mutex<Phase>) -> Result<(), String> {
        let mut c = lock(&self.counts);
        let mut p = lock(phase);
        if *p != Phase::Pending {
            return Ok(());
        }
        c.pending -= 1;
        if c.watching >= self.limits.max_clients {
            *p = Phase::Full;
            return Err(self.full_text(c.watching));
        }
        c.watching += 1;
        *p = Phase::Watching;
        Ok(())
    }

    fn full_text(&self, watching: usize) -> String {
        format!("{watching} watchers already, the most this server takes; try again later")
    }

    /// Gives back what an admitted connection held.
    fn leave(&self, ip: IpAddr, phase: Phase) {
        let mut c = lock(&self.counts);
        match phase {
            Phase::Pending => c.pending -= 1,
            Phase::Watching => c.watching -= 1,
            Phase::Full => {}
        }
        if let Some(n) = c.by_address.get_mut(&ip) {
            *n -= 1;
            if *n == 0 {
                c.by_address.remove(&ip);
            }
        }
    }
}

pub(super) fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// The russh configuration: the host key, key or no authentication, no idle
/// garbage collection by russh (the viewer's idle limit and keepalives do it).
#[must_use]
pub fn russh_config(key: PrivateKey, public: bool) -> russh::server::Config {
    let methods: &[MethodKind] = if public {
        &[MethodKind::None]
    } else {
        &[MethodKind::PublicKey]
    };
    russh::server::Config {
        server_id: russh::SshId::Standard("SSH-2.0-termrast".into()),
        methods: methods.into(),
        auth_rejection_time: Duration::from_millis(500),
        auth_rejection_time_initial: Some(Duration::ZERO),
        keys: vec![key],
        max_auth_attempts: MAX_AUTH_ATTEMPTS,
        inactivity_timeout: None,
        keepalive_interval: Some(Duration::from_secs(15)),
        keepalive_max: 4,
        nodelay: true,
        ..Default::default()
    }
}

/// Accepts connections until `stop` resolves; then ends every session with a
/// message and returns once they are gone (or after a few seconds).
pub async fn serve(
    listener: TcpListener,
    config: Arc<russh::server::Config>,
    state: Arc<State>,
    stop: impl std::future::Future<Output = ()>,
) {
    tokio::pin!(stop);
    loop {
        tokio::select! {
            r = listener.accept() => match r {
                Ok((sock, peer)) => {
                    let (config, state) = (Arc::clone(&config), Arc::clone(&state));
                    tokio::spawn(connection(sock, peer, config, state));
                }
                // Out of descriptors, say: wait a little rather than spin.
                Err(_) => tokio::time::sleep(Duration::from_millis(50)).await,
            },
            () = &mut stop => break,
        }
    }
    drop(listener);
    for w in lock(&state.watchers).values() {
        let _ = w.try_send(crate::tui::Wake::Signal(libc::SIGTERM));
    }
    let until = Instant::now() + Duration::from_secs(3);
    while Instant::now() < until && !lock(&state.handles).is_empty() {
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let left: Vec<Handle> = lock(&state.handles).values().cloned().collect();
    for h in left {
        let _ = h
            .disconnect(
                Disconnect::ByApplication,
                "termrast: the server is shutting down".into(),
                String::new(),
            )
            .await;
    }
    let until = Instant::now() + Duration::from_secs(2);
    while Instant::now() < until && !lock(&state.handles).is_empty() {
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

async fn connection(
    sock: TcpStream,
    peer: SocketAddr,
    config: Arc<russh::server::Config>,
    state: Arc<State>,
) {
    let start = Instant::now();
    let when = SystemTime::now();
    // A second handle on the socket, to shut it down under a session stuck writing
    // to a client that reads nothing (dropping the session would leave its task
    // running, and its handle's calls wait on that stuck loop).
    let (sock, closer) = match split_closer(sock) {
        Ok(pair) => pair,
        Err(e) => {
            eprintln!("{} {peer} end=error: {e}", utc(when));
            return;
        }
    };
    let id = state.next_id.fetch_add(1, Ordering::Relaxed);
    let refuse = match state.arrive(peer.ip(), id) {
        Arrival::Admitted => None,
        Arrival::Dropped => return,
        Arrival::Refused(why) => {
            let mut n = lock(&state.refusing);
            if *n >= MAX_REFUSING {
                return;
            }
            *n += 1;
            Some(why)
        }
    };
    // Frames end in a small query: without this, Nagle holds it for the ACK of the
    // frame, and every frame waits a delayed ACK (run_stream does not set it).
    let _ = sock.set_nodelay(true);
    let log = Arc::new(Mutex::new(Log::default()));
    let phase = Arc::new(Mutex::new(Phase::Pending));
    let (done_tx, done_rx) = oneshot::channel();
    let (kill_tx, kill_rx) = oneshot::channel::<()>();
    let conn = Conn {
        id,
        state: Arc::clone(&state),
        refuse: refuse.clone(),
        full: None,
        log: Arc::clone(&log),
        phase: Arc::clone(&phase),
        channel: None,
        write: None,
        req: Request::default(),
        watcher: None,
        done: Some(done_tx),
        kill: Some(kill_tx),
    };
    let grace = state.limits.login_grace;
    let result = tokio::time::timeout(grace, russh::server::run_stream(config, sock, conn)).await;
    match result {
        Ok(Ok(running)) => {
            let handle = running.handle();
            lock(&state.handles).insert(id, handle.clone());
            // Authenticate within the grace time, or go.
            let phase = Arc::clone(&phase);
            let grace = tokio::spawn(async move {
                tokio::time::sleep(grace).await;
                if *lock(&phase) == Phase::Pending {
                    let _ = handle
                        .disconnect(
                            Disconnect::ByApplication,
                            "authentication timed out".into(),
                            String::new(),
                        )
                        .await;
                }
            });
            // A stalled watcher's kill shuts the socket down: the session's reads
            // see its end and its writes fail, so it ends by itself.
            let killed = async {
                if kill_rx.await.is_err() {
                    std::future::pending::<()>().await;
                }
            };
            tokio::pin!(running);
            let r = tokio::select! {
                r = &mut running => r,
                () = killed => {
                    let _ = closer.shutdown(std::net::Shutdown::Both);
                    running.await
                }
            };
            grace.abort();
            if let Err(e) = r {
                let mut l = lock(&log);
                // A client that leaves without saying so is not an error of ours.
                let eof = e.to_string().contains("eof");
                if l.end.is_none() && !(eof && l.key.is_some()) {
                    l.end = Some(if eof {
                        "not authenticated".into()
                    } else {
                        format!("error: {e}")
                    });
                }
            }
        }
        Ok(Err(e)) => lock(&log).end = Some(format!("handshake: {e}")),
        Err(_) => lock(&log).end = Some("handshake timed out".into()),
    }
    lock(&state.watchers).remove(&id);
    // The watcher's own account of its end, once its channel is closed.
    if let Ok(Ok((end, bytes))) = tokio::time::timeout(Duration::from_secs(5), done_rx).await {
        let mut l = lock(&log);
        l.bytes = bytes;
        l.end = Some(end.to_string());
    }
    match &refuse {
        Some(why) => {
            *lock(&state.refusing) -= 1;
            lock(&log).end = Some(format!("refused: {why}"));
        }
        None => state.leave(peer.ip(), *lock(&phase)),
    }
    let l = lock(&log);
    let end = l.end.clone().unwrap_or_else(|| {
        if l.key.is_some() {
            "client closed".into()
        } else {
            "not authenticated".into()
        }
    });
    eprintln!(
        "{} {peer} key={} size={} duration={:.1}s sent={} end={end}",
        utc(when),
        l.key.as_deref().unwrap_or("-"),
        l.size.map_or("-".into(), |(c, r)| format!("{c}x{r}")),
        start.elapsed().as_secs_f64(),
        l.bytes,
    );
    // Last: shutdown waits for this, so the line above is never lost.
    lock(&state.handles).remove(&id);
}

/// The socket for the session, and a clone of it that can shut it down.
fn split_closer(sock: TcpStream) -> std::io::Result<(TcpStream, std::net::TcpStream)> {
    let std_sock = sock.into_std()?;
    let closer = std_sock.try_clone()?;
    Ok((TcpStream::from_std(std_sock)?, closer))
}

/// `2026-12-03T10:52:35Z`.
#[must_use]
pub fn utc(t: SystemTime) -> String {
    let secs = t
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (days, rem) = (secs / 86400, secs % 86400);
    // Howard Hinnant's days-to-civil.
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_times() {
        assert_eq!(utc(SystemTime::UNIX_EPOCH), "1970-01-01T00:00:00Z");
        let t = SystemTime::UNIX_EPOCH + Duration::from_secs(1_796_294_355);
        assert_eq!(utc(t), "2026-12-03T10:39:15Z");
        let t = SystemTime::UNIX_EPOCH + Duration::from_secs(951_782_400);
        assert_eq!(utc(t), "2000-02-29T00:00:00Z");
    }
}
