//! The host key and the keys admitted to watch.
//!
//! The host key is what lets a watcher tell this server from an impostor, so it is
//! made once (Ed25519, from the system's random source) and kept: written with mode
//! 0600 into a directory made 0700, and refused when group or others may read it or
//! it belongs to another user, as sshd refuses such keys.

use std::collections::HashSet;
use std::fs;
use std::io::{Read, Write};
use std::os::unix::fs::{DirBuilderExt, MetadataExt, OpenOptionsExt, PermissionsExt};
use std::path::{Path, PathBuf};

use russh::keys::ssh_key::LineEnding;
use russh::keys::ssh_key::private::Ed25519Keypair;
use russh::keys::ssh_key::public::KeyData;
use russh::keys::{HashAlg, PrivateKey, PublicKey};

/// Why a key could not be had.
#[derive(Debug, thiserror::Error)]
pub enum KeyError {
    #[error(
        "host key {0}: readable by group or others (mode {1:o}); `chmod 600 {0}` and start again"
    )]
    Exposed(PathBuf, u32),
    #[error("host key {0}: owned by another user (uid {1})")]
    NotOwned(PathBuf, u32),
    #[error("host key {0}: {1}")]
    Io(PathBuf, std::io::Error),
    #[error("host key {0}: not an OpenSSH private key ({1})")]
    Format(PathBuf, String),
    #[error("authorized keys {0}: {1}")]
    Authorized(PathBuf, String),
}

/// The host key in `path`, made there first if the file does not exist. Returns
/// the key and whether it was just made.
pub fn host_key(path: &Path) -> Result<(PrivateKey, bool), KeyError> {
    let io = |e| KeyError::Io(path.to_path_buf(), e);
    match fs::symlink_metadata(path) {
        Ok(meta) => {
            check_private(path, &meta)?;
            let mut text = String::new();
            fs::File::open(path)
                .and_then(|f| f.take(64 * 1024).read_to_string(&mut text))
                .map_err(io)?;
            let key = PrivateKey::from_openssh(text.as_bytes())
                .map_err(|e| KeyError::Format(path.to_path_buf(), e.to_string()))?;
            Ok((key, false))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok((make_host_key(path)?, true)),
        Err(e) => Err(io(e)),
    }
}

/// Refuses a key file others may read, or that is not a regular file of ours.
fn check_private(path: &Path, meta: &fs::Metadata) -> Result<(), KeyError> {
    if !meta.file_type().is_file() {
        return Err(KeyError::Format(
            path.to_path_buf(),
            "not a regular file".into(),
        ));
    }
    let mode = meta.permissions().mode() & 0o777;
    if mode & 0o077 != 0 {
        return Err(KeyError::Exposed(path.to_path_buf(), mode));
    }
    // SAFETY: geteuid has no preconditions.
    let me = unsafe { libc::geteuid() };
    if meta.uid() != me {
        return Err(KeyError::NotOwned(path.to_path_buf(), meta.uid()));
    }
    Ok(())
}

fn make_host_key(path: &Path) -> Result<PrivateKey, KeyError> {
    let io = |e| KeyError::Io(path.to_path_buf(), e);
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(dir)
            .map_err(io)?;
    }
    let mut seed = [0u8; 32];
    fs::File::open("/dev/urandom")
        .and_then(|mut f| f.read_exact(&mut seed))
        .map_err(io)?;
    let key = PrivateKey::from(Ed25519Keypair::from_seed(&seed));
    seed.fill(0);
    let text = key
        .to_openssh(LineEnding::LF)
        .map_err(|e| KeyError::Format(path.to_path_buf(), e.to_string()))?;
    // create_new: never follow a planted link or overwrite a file made meanwhile.
    let mut f = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o600)
        .open(path)
        .map_err(io)?;
    f.write_all(text.as_bytes())
        .and_then(|()| f.sync_all())
        .map_err(io)?;
    Ok(key)
}

/// A key's SHA256 fingerprint as OpenSSH prints it (`SHA256:…`).
#[must_use]
pub fn fingerprint(key: &PublicKey) -> String {
    key.fingerprint(HashAlg::Sha256).to_string()
}

/// The public keys admitted to watch.
#[derive(Debug, Default)]
pub struct Authorized {
    keys: HashSet<KeyData>,
}

impl Authorized {
    /// Reads an OpenSSH `authorized_keys` file: one key a line, `#` comments, options
    /// before the key type skipped (none of them grants anything here).
    pub fn load(path: &Path) -> Result<Self, KeyError> {
        let err = |m: String| KeyError::Authorized(path.to_path_buf(), m);
        let mut text = String::new();
        fs::File::open(path)
            .and_then(|f| f.take(4 << 20).read_to_string(&mut text))
            .map_err(|e| err(e.to_string()))?;
        let a = Self::parse(&text).map_err(err)?;
        if a.keys.is_empty() {
            return Err(err("no keys in it".into()));
        }
        Ok(a)
    }

    /// Keys from the text of an `authorized_keys` file.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut keys = HashSet::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let key = PublicKey::from_openssh(line).or_else(|e| {
                // Options first (`from="…",no-pty ssh-ed25519 AAAA…`): from the key type on.
                let at = line
                    .find(" ssh-")
                    .or_else(|| line.find(" ecdsa-"))
                    .or_else(|| line.find(" sk-"))
                    .ok_or(e)?;
                PublicKey::from_openssh(line[at..].trim())
            });
            match key {
                Ok(k) => {
                    keys.insert(k.key_data().clone());
                }
                Err(e) => return Err(format!("line {}: {e}", n + 1)),
            }
        }
        Ok(Self { keys })
    }

    /// Whether `key` is one of them (compared by its key data, not its comment).
    #[must_use]
    pub fn admits(&self, key: &PublicKey) -> bool {
        self.keys.contains(key.key_data())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("termrast-keys-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn a_host_key_is_made_private_kept_and_refused_when_exposed() {
        let dir = temp("host");
        let path = dir.join("sub/host_ed25519");
        let (made, new) = host_key(&path).expect("made");
        assert!(new);
        let mode = fs::metadata(&path).expect("exists").permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);
        let dmode = fs::metadata(path.parent().unwrap())
            .unwrap()
            .permissions()
            .mode()
            & 0o777;
        assert_eq!(dmode, 0o700);
        let (again, new) = host_key(&path).expect("loaded");
        assert!(!new);
        assert_eq!(
            fingerprint(made.public_key()),
            fingerprint(again.public_key())
        );
        assert!(fingerprint(made.public_key()).starts_with("SHA256:"));
        fs::set_permissions(&path, fs::Permissions::from_mode(0o644)).unwrap();
        assert!(matches!(host_key(&path), Err(KeyError::Exposed(_, 0o644))));
        fs::set_permissions(&path, fs::Permissions::from_mode(0o640)).unwrap();
        assert!(matches!(host_key(&path), Err(KeyError::Exposed(..))));
        let _ = fs::remove_dir_all(&dir);
    }

    #[test]
    fn authorized_keys_by_key_data() {
        let a = PrivateKey::from(Ed25519Keypair::from_seed(&[1; 32]));
        let b = PrivateKey::from(Ed25519Keypair::from_seed(&[2; 32]));
        let line = a.public_key().to_openssh().unwrap();
        let text = format!("# comment\n\nno-pty,from=\"10.0.0.0/8\" {line} someone@host\n");
        let auth = Authorized::parse(&text).expect("parses");
        assert!(auth.admits(a.public_key()));
        assert!(!auth.admits(b.public_key()));
        assert!(Authorized::parse("ssh-ed25519 notbase64").is_err());
    }
}
