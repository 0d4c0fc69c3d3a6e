//! A connection as russh's handler: authentication, and what a session may ask for.
//!
//! It admits keys (or anyone, when public), keeps what the pty and environment
//! requests say, and starts the viewer on the shell request. Everything else a
//! client may ask (commands, subsystems, forwarding of ports, agent or X11, a second
//! session) is refused, so nothing it sends runs a program, opens a file or opens a
//! connection.

use std::sync::{Arc, Mutex};

use russh::server::{Auth, ChannelOpenHandle, Handler, Msg, Session};
use russh::{Channel, ChannelId, ChannelOpenFailure, ChannelWriteHalf};
use tokio::sync::oneshot;

use super::keys::fingerprint;
use super::server::{Admit, Phase, State, lock};
use super::session::{self, Outcome, Request, Watcher};

/// What a connection's log line says.
#[derive(Debug, Default)]
pub(super) struct Log {
    pub(super) key: Option<String>,
    pub(super) size: Option<(u16, u16)>,
    pub(super) bytes: u64,
    pub(super) end: Option<String>,
}

/// A connection: russh's handler.
pub(super) struct Conn {
    pub(super) id: u64,
    pub(super) state: Arc<State>,
    /// Refused for this reason (too many watchers): told in the banner, never admitted.
    pub(super) refuse: Option<String>,
    /// Authenticated when every watcher's place was taken: told this, then closed.
    pub(super) full: Option<String>,
    pub(super) log: Arc<Mutex<Log>>,
    pub(super) phase: Arc<Mutex<Phase>>,
    pub(super) channel: Option<ChannelId>,
    pub(super) write: Option<ChannelWriteHalf<Msg>>,
    pub(super) req: Request,
    pub(super) watcher: Option<Watcher>,
    pub(super) done: Option<oneshot::Sender<Outcome>>,
    /// Closes the connection outright (a stalled client).
    pub(super) kill: Option<oneshot::Sender<()>>,
}

impl Conn {
    fn ours(&self, channel: ChannelId) -> bool {
        self.channel == Some(channel)
    }

    fn accept(&mut self, key: String) -> Auth {
        lock(&self.log).key = Some(key);
        if let Err(why) = self.state.authenticated(&self.phase) {
            self.full = Some(why);
        }
        Auth::Accept
    }

    /// Ends a session with one line of text instead of the viewer, logging `why`.
    fn refuse_shell(
        &self,
        session: &mut Session,
        channel: ChannelId,
        why: &str,
        text: &str,
    ) -> Result<(), russh::Error> {
        lock(&self.log).end = Some(format!("refused: {why}"));
        session.channel_success(channel)?;
        session.data(channel, format!("termrast: {text}\r\n").into_bytes())?;
        session.exit_status_request(channel, 1)?;
        session.eof(channel)?;
        session.close(channel)
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
        if let Some(why) = &self.full {
            return self.refuse_shell(session, channel, why, why);
        }
        if self.req.pty.is_none() {
            let text = "this server shows a 3D viewer and needs a terminal; \
                        connect with `ssh -t`";
            return self.refuse_shell(session, channel, "no pty", text);
        }
        // One shell per connection: `write` above is taken by the first.
        let (Some(done), Some(kill)) = (self.done.take(), self.kill.take()) else {
            return session.channel_failure(channel);
        };
        match session::start(
            &self.state.shared,
            &self.req,
            write,
            session.handle(),
            channel,
            done,
            kill,
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
            match (&self.watcher, &mut self.req.pty) {
                (Some(w), _) => w.tell(crate::tui::Wake::Resize(c, r)),
                // Before the shell: the viewer starts at this size.
                (None, Some(pty)) => (pty.1, pty.2) = (c, r),
                (None, None) => {}
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
