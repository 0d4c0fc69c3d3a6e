//! The SSH side: accepting connections within the limits, authentication, what a
//! session may ask for, one log line per connection, and shutting down.
//!
//! Each connection gets a [`Conn`], russh's handler: it admits keys (or anyone, when
//! public), keeps what the pty and environment requests say, and starts the viewer
//! on the shell request. Everything else a client may ask (commands, subsystems,
//! forwarding of ports, agent or X11, a second session) is refused, so nothing it
//! sends runs a program, opens a file or opens a connection.

use std::collections::HashMap;
use std::net::{IpAddr, SocketAddr};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

use russh::keys::PrivateKey;
use russh::server::{Auth, ChannelOpenHandle, Handle, Handler, Msg, Session};
use russh::{Channel, ChannelId, ChannelOpenFailure, ChannelWriteHalf, Disconnect, MethodKind};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::oneshot;

use super::keys::{Authorized, fingerprint};
use super::session::{self, Outcome, Request, Shared, Watcher};

/// Time from connecting to being authenticated (as sshd's LoginGraceTime).
pub const LOGIN_GRACE: Duration = Duration::from_secs(30);
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

/// The server's state, shared by its connections.
#[derive(Debug)]
pub struct State {
    pub shared: Arc<Shared>,
    pub admit: Admit,
    pub max_clients: usize,
    pub max_per_address: usize,
    /// Connections admitted (not refused), by address.
    open: Mutex<HashMap<IpAddr, usize>>,
    refusing: Mutex<usize>,
    /// Running watchers, to end them on shutdown; and every connection's handle.
    watchers: Mutex<HashMap<u64, std::sync::mpsc::SyncSender<crate::tui::Wake>>>,
    handles: Mutex<HashMap<u64, Handle>>,
    next_id: AtomicU64,
}

impl State {
    #[must_use]
    pub fn new(
        shared: Arc<Shared>,
        admit: Admit,
        max_clients: usize,
        max_per_address: usize,
    ) -> Self {
        Self {
            shared,
            admit,
            max_clients,
            max_per_address,
            open: Mutex::default(),
            refusing: Mutex::default(),
            watchers: Mutex::default(),
            handles: Mutex::default(),
            next_id: AtomicU64::new(0),
        }
    }

    /// Admits a connection from `ip`, or says why not.
    fn admit(&self, ip: IpAddr) -> Result<(), String> {
        let mut open = lock(&self.open);
        let total: usize = open.values().sum();
        if total >= self.max_clients {
            return Err(format!(
                "{total} watchers already, the most this server takes; try again later"
            ));
        }
        let here = open.entry(ip).or_insert(0);
        if *here >= self.max_per_address {
            return Err(format!(
                "{here} connections from {ip} already, the most it takes"
            ));
        }
        *here += 1;
        Ok(())
    }

    fn release(&self, ip: IpAddr) {
        let mut open = lock(&self.open);
        if let Some(n) = open.get_mut(&ip) {
            *n -= 1;
            if *n == 0 {
                open.remove(&ip);
            }
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
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

/// What a connection's log line says.
#[derive(Debug, Default)]
struct Log {
    key: Option<String>,
    size: Option<(u16, u16)>,
    bytes: u64,
    end: Option<String>,
}

/// A connection: russh's handler.
struct Conn {
    id: u64,
    state: Arc<State>,
    /// Refused for this reason (too many watchers): told in the banner, never admitted.
    refuse: Option<String>,
    log: Arc<Mutex<Log>>,
    authed: Arc<AtomicBool>,
    channel: Option<ChannelId>,
    write: Option<ChannelWriteHalf<Msg>>,
    req: Request,
    watcher: Option<Watcher>,
    done: Option<oneshot::Sender<Outcome>>,
}

impl Conn {
    fn ours(&self, channel: ChannelId) -> bool {
        self.channel == Some(channel)
    }

    fn accept(&mut self, key: String) -> Auth {
        lock(&self.log).key = Some(key);
        self.authed.store(true, Ordering::Release);
        Auth::Accept
    }
}

impl Drop for Conn {
    fn drop(&mut self) {
        if let Some(w) = &self.watcher {
            w.tell(crate::tui::Wake::Eof);
        }
    }
}

impl Handler for Conn {
    type Error = russh::Error;

    async fn authentication_banner(&mut self) -> Result<Option<String>, Self::Error> {
        Ok(self.refuse.as_ref().map(|r| format!("termrast: {r}\r\n")))
    }

    async fn auth_none(&mut self, _user: &str) -> Result<Auth, Self::Error> {
        if self.refuse.is_none() && matches!(self.state.admit, Admit::Public) {
            return Ok(self.accept("public".into()));
        }
        Ok(Auth::reject())
    }

    async fn auth_publickey_offered(
        &mut self,
        _user: &str,
        offer: russh::server::PublicKeyOffer<'_>,
    ) -> Result<Auth, Self::Error> {
        Ok(match &self.state.admit {
            Admit::Keys(a) if self.refuse.is_none() && a.admits(offer.public_key) => Auth::Accept,
            _ => Auth::reject(),
        })
    }

    async fn auth_publickey(
        &mut self,
        _user: &str,
        key: russh::server::VerifiedPublicKey<'_>,
    ) -> Result<Auth, Self::Error> {
        Ok(match &self.state.admit {
            Admit::Keys(a) if self.refuse.is_none() && a.admits(key.public_key) => {
                self.accept(fingerprint(key.public_key))
            }
            _ => Auth::reject(),
        })
    }

    async fn channel_open_session(
        &mut self,
        channel: Channel<Msg>,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        if self.channel.is_some() {
            reply
                .reject(ChannelOpenFailure::AdministrativelyProhibited)
                .await;
            return Ok(());
        }
        self.channel = Some(channel.id());
        // Requests and data come through this handler; the read half is not read.
        let (_read, write) = channel.split();
        self.write = Some(write);
        reply.accept().await;
        Ok(())
    }

    async fn channel_open_x11(
        &mut self,
        _channel: Channel<Msg>,
        _address: &str,
        _port: u32,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        reply
            .reject(ChannelOpenFailure::AdministrativelyProhibited)
            .await;
        Ok(())
    }

    async fn channel_open_direct_tcpip(
        &mut self,
        _channel: Channel<Msg>,
        _host: &str,
        _port: u32,
        _from: &str,
        _from_port: u32,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        lock(&self.log).end = Some("refused: port forwarding".into());
        reply
            .reject(ChannelOpenFailure::AdministrativelyProhibited)
            .await;
        Ok(())
    }

    async fn channel_open_direct_streamlocal(
        &mut self,
        _channel: Channel<Msg>,
        _path: &str,
        reply: ChannelOpenHandle,
        _session: &mut Session,
    ) -> Result<(), Self::Error> {
        reply
            .reject(ChannelOpenFailure::AdministrativelyProhibited)
            .await;
        Ok(())
    }

    async fn tcpip_forward(
        &mut self,
        _: &str,
        _: &mut u32,
        _: &mut Session,
    ) -> Result<bool, Self::Error> {
        lock(&self.log).end = Some("refused: remote forwarding".into());
        Ok(false)
    }

    async fn streamlocal_forward(&mut self, _: &str, _: &mut Session) -> Result<bool, Self::Error> {
        Ok(false)
    }

    async fn agent_request(&mut self, _: ChannelId, _: &mut Session) -> Result<bool, Self::Error> {
        Ok(false)
    }

    async fn x11_request(
        &mut self,
        channel: ChannelId,
        _: bool,
        _: &str,
        _: &str,
        _: u32,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        session.channel_failure(channel)
    }

    async fn pty_request(
        &mut self,
        channel: ChannelId,
        term: &str,
        cols: u32,
        rows: u32,
        _pix_width: u32,
        _pix_height: u32,
        _modes: &[(russh::Pty, u32)],
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        if !self.ours(channel) || self.watcher.is_some() || term.len() > 64 {
            return session.channel_failure(channel);
        }
        let (c, r) = session::clamp_size(cols, rows);
        self.req.pty = Some((term.to_string(), c, r));
        lock(&self.log).size = Some((c, r));
        session.channel_success(channel)
    }

    async fn env_request(
        &mut self,
        channel: ChannelId,
        name: &str,
        value: &str,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        if self.ours(channel) && self.watcher.is_none() && self.req.set_env(name, value) {
            session.channel_success(channel)
        } else {
            session.channel_failure(channel)
        }
    }

    async fn shell_request(
        &mut self,
        channel: ChannelId,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        let Some(write) = self.write.take().filter(|_| self.ours(channel)) else {
            return session.channel_failure(channel);
        };
        if self.req.pty.is_none() {
            session.channel_success(channel)?;
            lock(&self.log).end = Some("refused: no pty".into());
            let text = "termrast: this server shows a 3D viewer and needs a terminal; \
                        connect with `ssh -t`\r\n";
            session.data(channel, text.as_bytes().to_vec())?;
            session.exit_status_request(channel, 1)?;
            session.eof(channel)?;
            return session.close(channel);
        }
        let done = self.done.take().expect("one shell per connection");
        match session::start(
            &self.state.shared,
            &self.req,
            write,
            session.handle(),
            channel,
            done,
        ) {
            Ok(w) => {
                lock(&self.state.watchers).insert(self.id, w.sender());
                self.watcher = Some(w);
                session.channel_success(channel)
            }
            Err(e) => {
                lock(&self.log).end = Some(format!("error: {e}"));
                session.channel_failure(channel)?;
                session.close(channel)
            }
        }
    }

    async fn exec_request(
        &mut self,
        channel: ChannelId,
        _: &[u8],
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        lock(&self.log).end = Some("refused: exec".into());
        session.channel_failure(channel)?;
        session.close(channel)
    }

    async fn subsystem_request(
        &mut self,
        channel: ChannelId,
        name: &str,
        session: &mut Session,
    ) -> Result<(), Self::Error> {
        lock(&self.log).end = Some(format!("refused: subsystem {}", name.escape_debug()));
        session.channel_failure(channel)?;
        session.close(channel)
    }

    async fn window_change_request(
        &mut self,
        channel: ChannelId,
        cols: u32,
        rows: u32,
        _: u32,
        _: u32,
        _: &mut Session,
    ) -> Result<(), Self::Error> {
        let (c, r) = session::clamp_size(cols, rows);
        if self.ours(channel) {
            lock(&self.log).size = Some((c, r));
            if let Some(w) = &self.watcher {
                w.tell(crate::tui::Wake::Resize(c, r));
            }
        }
        Ok(())
    }

    async fn data(
        &mut self,
        channel: ChannelId,
        data: &[u8],
        _: &mut Session,
    ) -> Result<(), Self::Error> {
        if self.ours(channel)
            && let Some(w) = &mut self.watcher
        {
            w.input(data);
        }
        Ok(())
    }

    async fn channel_eof(
        &mut self,
        channel: ChannelId,
        _: &mut Session,
    ) -> Result<(), Self::Error> {
        if self.ours(channel)
            && let Some(w) = &self.watcher
        {
            w.tell(crate::tui::Wake::Eof);
        }
        Ok(())
    }

    async fn channel_close(
        &mut self,
        channel: ChannelId,
        s: &mut Session,
    ) -> Result<(), Self::Error> {
        self.channel_eof(channel, s).await
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
    let refuse = match state.admit(peer.ip()) {
        Ok(()) => None,
        Err(why) => {
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
    let id = state.next_id.fetch_add(1, Ordering::Relaxed);
    let log = Arc::new(Mutex::new(Log::default()));
    let authed = Arc::new(AtomicBool::new(false));
    let (done_tx, done_rx) = oneshot::channel();
    let conn = Conn {
        id,
        state: Arc::clone(&state),
        refuse: refuse.clone(),
        log: Arc::clone(&log),
        authed: Arc::clone(&authed),
        channel: None,
        write: None,
        req: Request::default(),
        watcher: None,
        done: Some(done_tx),
    };
    let result =
        tokio::time::timeout(LOGIN_GRACE, russh::server::run_stream(config, sock, conn)).await;
    match result {
        Ok(Ok(running)) => {
            let handle = running.handle();
            lock(&state.handles).insert(id, handle.clone());
            // Authenticate within the grace time, or go.
            let grace = tokio::spawn(async move {
                tokio::time::sleep(LOGIN_GRACE).await;
                if !authed.load(Ordering::Acquire) {
                    let _ = handle
                        .disconnect(
                            Disconnect::ByApplication,
                            "authentication timed out".into(),
                            String::new(),
                        )
                        .await;
                }
            });
            let r = running.await;
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
        None => state.release(peer.ip()),
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
