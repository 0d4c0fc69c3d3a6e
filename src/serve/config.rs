//! `termrast serve`'s arguments and the checks made before anything listens.

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

/// What `termrast serve --help` says about who may connect and what they get.
pub const SECURITY: &str = "\
Security: every watcher gets the viewer and nothing else. Commands (ssh host CMD),
subsystems (sftp), port, agent and X11 forwarding are refused; a session without a
terminal is told so and closed. Nothing a client sends runs a program, opens a file
or reaches the network. Who may watch: the keys in --authorized-keys (OpenSSH
format), or anyone with --public; listening beyond loopback requires one of them
(on loopback, neither means ~/.ssh/authorized_keys). Limits: --max-clients
watchers, --max-per-address, --max-startups unauthenticated connections (past
it, new ones are dropped at random), 6 authentication attempts within
--login-grace-time, --idle-timeout, --stall-timeout; watchers share
--render-slots frames at once by rendering time.
The host key (Ed25519) is made on first start, kept with mode 0600 (refused if
others can read it); check its fingerprint, printed at start, on first connect.";

/// Arguments of `termrast serve`.
#[derive(Debug, Args, Clone)]
#[command(after_help = SECURITY)]
pub struct ServeArgs {
    /// `teapot` or `bunny` (built in), `sphere:N`, a model path, or a scene file
    /// `SCENE.toml`; loaded once and shared by every watcher.
    #[arg(default_value = "teapot")]
    pub model: String,
    /// Address and port to listen on (port 0 picks a free one).
    #[arg(long, default_value = "127.0.0.1:2222", value_name = "ADDR:PORT")]
    pub listen: SocketAddr,
    /// The host key (OpenSSH format), made on first start; by default
    /// `$XDG_STATE_HOME/termrast/host_ed25519` (or `~/.local/state/termrast/…`).
    #[arg(long, value_name = "FILE")]
    pub host_key: Option<PathBuf>,
    /// Admit the public keys in this file (OpenSSH `authorized_keys` format).
    #[arg(long, value_name = "FILE", conflicts_with = "public")]
    pub authorized_keys: Option<PathBuf>,
    /// Admit anyone, without authentication.
    #[arg(long)]
    pub public: bool,
    /// Watchers at once; more are refused with a message.
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub max_clients: u32,
    /// Connections at once from one address.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub max_per_address: u32,
    /// Close a session after this long without a key or mouse event (`90s`, `30m`,
    /// `2h`; `0` never).
    #[arg(long, default_value = "30m", value_parser = parse_duration)]
    pub idle_timeout: Duration,
    /// Frame rate cap of each watcher.
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=240))]
    pub fps: u32,
    /// Frames rendered at once for all watchers together (default: the cores); when
    /// the CPU is short, watchers share them by rendering time.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=256))]
    pub render_slots: Option<u32>,
    /// Connections not yet authenticated, as OpenSSH's MaxStartups: past START of
    /// them, new ones are dropped with probability RATE %, rising to every one at
    /// FULL. They do not count against --max-clients.
    #[arg(long, default_value = "10:30:60", value_name = "START:RATE:FULL", value_parser = Startups::parse)]
    pub max_startups: Startups,
    /// Time from connecting to being authenticated.
    #[arg(long, default_value = "30s", value_parser = parse_duration)]
    pub login_grace_time: Duration,
    /// Close a session whose client has taken no output for this long.
    #[arg(long, default_value = "30s", value_parser = parse_duration)]
    pub stall_timeout: Duration,
}

/// The limit on connections not yet authenticated (see [`ServeArgs::max_startups`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Startups {
    pub start: usize,
    /// Percent.
    pub rate: usize,
    pub full: usize,
}

impl Startups {
    /// Parses `START:RATE:FULL` (or a single number, as OpenSSH: drop all past it).
    pub fn parse(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}` is not START:RATE:FULL (e.g. 10:30:60) or a count");
        let n: Vec<usize> = s
            .split(':')
            .map(|p| p.trim().parse().map_err(|_| bad()))
            .collect::<Result<_, _>>()?;
        let l = match n[..] {
            [full] => Self {
                start: full,
                rate: 100,
                full,
            },
            [start, rate, full] => Self { start, rate, full },
            _ => return Err(bad()),
        };
        if l.full == 0 || l.start > l.full || l.rate > 100 || l.full > 100_000 {
            return Err(format!(
                "`{s}`: need 0 < START <= FULL <= 100000 and RATE <= 100"
            ));
        }
        Ok(l)
    }

    /// Whether a new connection is dropped when `pending` are waiting to
    /// authenticate, for a uniform `roll` in 0..100.
    #[must_use]
    pub fn drops(&self, pending: usize, roll: usize) -> bool {
        if pending >= self.full {
            return true;
        }
        if pending < self.start {
            return false;
        }
        let chance =
            self.rate + (100 - self.rate) * (pending - self.start) / (self.full - self.start);
        roll < chance
    }
}

/// Who may watch.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Access {
    /// Keys read from this file.
    Keys(PathBuf),
    Public,
}

impl ServeArgs {
    /// Who may watch; `None` (no choice made) is allowed only on loopback, where it
    /// means the keys of the user running the server (`~/.ssh/authorized_keys`).
    pub fn access(&self) -> Result<Access, String> {
        if self.public {
            return Ok(Access::Public);
        }
        if let Some(p) = &self.authorized_keys {
            return Ok(Access::Keys(p.clone()));
        }
        if !self.listen.ip().is_loopback() {
            return Err(format!(
                "listening on {} (beyond this machine) needs --authorized-keys FILE or \
                 --public: say who may watch",
                self.listen
            ));
        }
        let home = std::env::var_os("HOME")
            .ok_or("no HOME for ~/.ssh/authorized_keys; give --authorized-keys FILE or --public")?;
        Ok(Access::Keys(
            PathBuf::from(home).join(".ssh/authorized_keys"),
        ))
    }

    /// The host key's file: given, or under the user's state directory.
    pub fn host_key_path(&self) -> Result<PathBuf, String> {
        if let Some(p) = &self.host_key {
            return Ok(p.clone());
        }
        let state = match std::env::var_os("XDG_STATE_HOME").filter(|v| !v.is_empty()) {
            Some(s) => PathBuf::from(s),
            None => PathBuf::from(
                std::env::var_os("HOME")
                    .ok_or("no HOME or XDG_STATE_HOME; give --host-key FILE")?,
            )
            .join(".local/state"),
        };
        Ok(state.join("termrast").join("host_ed25519"))
    }

    /// The idle limit, if any.
    #[must_use]
    pub fn idle(&self) -> Option<Duration> {
        (!self.idle_timeout.is_zero()).then_some(self.idle_timeout)
    }
}

/// Parses `90s`, `30m`, `2h` or plain seconds.
pub fn parse_duration(s: &str) -> Result<Duration, String> {
    let t = s.trim();
    let (num, unit) = t.split_at(t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len()));
    let n: u64 = num
        .parse()
        .map_err(|_| format!("`{s}` is not a duration such as 90s, 30m or 2h"))?;
    let secs = match unit {
        "" | "s" => n,
        "m" => n.saturating_mul(60),
        "h" => n.saturating_mul(3600),
        _ => return Err(format!("`{s}`: the unit is s, m or h")),
    };
    Ok(Duration::from_secs(secs))
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    use super::*;

    #[derive(Parser)]
    struct Cmd {
        #[command(flatten)]
        serve: ServeArgs,
    }

    fn args(a: &[&str]) -> ServeArgs {
        Cmd::try_parse_from(std::iter::once("serve").chain(a.iter().copied()))
            .expect("parses")
            .serve
    }

    #[test]
    fn beyond_loopback_who_may_watch_is_said_explicitly() {
        assert!(args(&["--listen", "0.0.0.0:2222"]).access().is_err());
        assert!(args(&["--listen", "[::]:2222"]).access().is_err());
        assert_eq!(
            args(&["--listen", "0.0.0.0:2222", "--public"]).access(),
            Ok(Access::Public)
        );
        assert_eq!(
            args(&["--listen", "10.0.0.1:22", "--authorized-keys", "k"]).access(),
            Ok(Access::Keys("k".into()))
        );
        assert!(
            Cmd::try_parse_from(["serve", "--public", "--authorized-keys", "k"]).is_err(),
            "both at once"
        );
    }

    #[test]
    fn durations() {
        assert_eq!(parse_duration("90s"), Ok(Duration::from_secs(90)));
        assert_eq!(parse_duration("30m"), Ok(Duration::from_secs(1800)));
        assert_eq!(parse_duration("2h"), Ok(Duration::from_secs(7200)));
        assert_eq!(parse_duration("5"), Ok(Duration::from_secs(5)));
        assert!(parse_duration("5d").is_err() && parse_duration("m").is_err());
        assert_eq!(args(&["--idle-timeout", "0"]).idle(), None);
    }

    #[test]
    fn startups_drop_more_as_more_wait() {
        let l = Startups::parse("10:30:60").expect("parses");
        assert_eq!(args(&[]).max_startups, l);
        assert!((0..100).all(|roll| !l.drops(9, roll)), "below START none");
        assert_eq!((0..100).filter(|&r| l.drops(10, r)).count(), 30);
        assert_eq!((0..100).filter(|&r| l.drops(35, r)).count(), 65);
        assert!((0..100).all(|roll| l.drops(60, roll)), "at FULL all");
        let one = Startups::parse("5").expect("parses");
        assert!(!one.drops(4, 99) && one.drops(5, 0));
        for bad in ["", "1:2", "10:30:5", "0", "10:101:60", "a:b:c", "1:2:3:4"] {
            assert!(Startups::parse(bad).is_err(), "{bad}");
        }
    }
}
