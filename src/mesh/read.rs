//! Reading a model file: regular files only, and never more than a limit, so a FIFO,
//! a device or a directory is refused at once instead of blocking or filling memory.

use std::fs::File;
use std::io::Read;
use std::path::Path;

use super::MeshError;

/// The largest model (or material library) file read, in bytes: 2 GiB, unless
/// [`LIMIT_VAR`] says otherwise.
pub const MAX_MODEL_BYTES: u64 = 2 << 30;

/// The environment variable that sets another limit (bytes, or with a `K`, `M`,
/// `G` suffix) for the model files of a run.
pub const LIMIT_VAR: &str = "TERMRAST_MAX_MODEL_BYTES";

/// The limit for model files: [`LIMIT_VAR`] if it is set to a size, else
/// [`MAX_MODEL_BYTES`].
#[must_use]
pub fn model_limit() -> u64 {
    std::env::var(LIMIT_VAR)
        .ok()
        .and_then(|v| parse_size(&v))
        .unwrap_or(MAX_MODEL_BYTES)
}

/// `123`, `64K`, `512M`, `4G` (powers of 1024).
fn parse_size(v: &str) -> Option<u64> {
    let v = v.trim();
    let (digits, unit) = match v.char_indices().last()? {
        (i, c) if c.is_ascii_alphabetic() => (&v[..i], c.to_ascii_uppercase()),
        _ => (v, ' '),
    };
    let n: u64 = digits.trim().parse().ok()?;
    let shift = match unit {
        ' ' | 'B' => 0,
        'K' => 10,
        'M' => 20,
        'G' => 30,
        'T' => 40,
        _ => return None,
    };
    n.checked_mul(1 << shift)
}

/// Reads `path` whole if it is a regular file of at most `limit` bytes. The file's
/// type is checked before it is opened (opening a FIFO blocks until a writer comes),
/// and the read stops past `limit` even if the file grows meanwhile.
pub fn read_regular(path: &Path, limit: u64) -> Result<Vec<u8>, MeshError> {
    let io = |source| MeshError::Io {
        path: path.into(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(MeshError::NotRegular {
            path: path.into(),
            what: file_kind(&meta),
        });
    }
    let too_large = |size| MeshError::TooLarge {
        path: path.into(),
        size,
        limit,
    };
    if meta.len() > limit {
        return Err(too_large(meta.len()));
    }
    let file = File::open(path).map_err(io)?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|source| MeshError::Io {
            path: path.into(),
            source,
        })?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// What a file that is not a regular file is, for the message.
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    "not a regular file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("123"), Some(123));
        assert_eq!(parse_size("64k"), Some(64 << 10));
        assert_eq!(parse_size(" 3G "), Some(3 << 30));
        assert_eq!(parse_size("1X"), None);
        assert_eq!(parse_size("G"), None);
        assert_eq!(parse_size("99999999999T"), None);
    }
}
