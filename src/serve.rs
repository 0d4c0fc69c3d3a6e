//! `termrast serve`: the viewer served over SSH, each watcher with their own view of
//! one shared model or scene.
//!
//! - [`config`]: the arguments and who may watch;
//! - [`keys`]: the host key (made once, kept private) and the admitted keys;
//! - [`server`]: connections, limits, the log, shutdown; `conn.rs`: authentication
//!   and refusals (russh's handler);
//! - [`session`]: a watcher's viewer on its own thread, bounded both ways;
//! - [`mod@bench`]: the load generator (`termrast bench serve`).
//!
//! It sits on top with `cli`: nothing below imports it.

pub mod bench;
pub mod config;
mod conn;
pub mod keys;
pub mod server;
pub mod session;

use std::sync::Arc;

use config::{Access, ServeArgs};
use server::{Admit, Limits, State};
use session::Shared;

use crate::tui::remote::RenderGate;

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    #[error("{0}")]
    Usage(String),
    #[error(transparent)]
    Key(#[from] keys::KeyError),
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// Runs the server until SIGTERM or SIGINT.
pub fn run(args: &ServeArgs) -> Result<(), ServeError> {
    let access = args.access().map_err(ServeError::Usage)?;
    let admit = match &access {
        Access::Public => Admit::Public,
        Access::Keys(p) => Admit::Keys(keys::Authorized::load(p)?),
    };
    let key_path = args.host_key_path().map_err(ServeError::Usage)?;
    let (key, made) = keys::host_key(&key_path)?;
    let scene = crate::cli::view_cmd::load(&args.model, crate::render::wire::Mode::Fill, false)?;
    let cores = std::thread::available_parallelism().map_or(2, std::num::NonZero::get);
    let slots = args.render_slots.map_or(cores, |n| n as usize);
    let shared = Arc::new(Shared {
        scene: Arc::new(scene),
        gate: Arc::new(RenderGate::new(slots)),
        fps: args.fps,
        idle: args.idle(),
        stall: args.stall_timeout.max(std::time::Duration::from_secs(1)),
    });
    let who = match &access {
        Access::Public => "anyone (--public)".to_string(),
        Access::Keys(p) => format!("the keys in {}", p.display()),
    };
    let fp = keys::fingerprint(key.public_key());
    let config = Arc::new(server::russh_config(key, admit_is_public(&admit)));
    let limits = Limits {
        max_clients: args.max_clients as usize,
        max_per_address: args.max_per_address as usize,
        startups: args.max_startups,
        login_grace: args.login_grace_time.max(std::time::Duration::from_secs(1)),
    };
    let state = Arc::new(State::new(shared, admit, limits));
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(cores.min(4))
        .enable_all()
        .build()?;
    rt.block_on(async {
        let listener = tokio::net::TcpListener::bind(args.listen).await?;
        let addr = listener.local_addr()?;
        let made = if made { ", made now" } else { "" };
        eprintln!(
            "termrast serve: {} for {who}\ntermrast serve: host key {} (ED25519{made}) {fp}\n\
             termrast serve: listening on {addr} (ssh -p {} {})",
            args.model,
            key_path.display(),
            addr.port(),
            addr.ip()
        );
        let stop = async {
            use tokio::signal::unix::{SignalKind, signal};
            match (
                signal(SignalKind::terminate()),
                signal(SignalKind::interrupt()),
            ) {
                (Ok(mut term), Ok(mut int)) => {
                    tokio::select! {
                        _ = term.recv() => {}
                        _ = int.recv() => {}
                    }
                }
                _ => std::future::pending().await,
            }
        };
        server::serve(listener, config, Arc::clone(&state), stop).await;
        eprintln!("termrast serve: stopped");
        Ok::<(), ServeError>(())
    })?;
    // Watcher threads still blocked on a vanished client are not waited for.
    rt.shutdown_timeout(std::time::Duration::from_secs(1));
    Ok(())
}

fn admit_is_public(a: &Admit) -> bool {
    matches!(a, Admit::Public)
}
