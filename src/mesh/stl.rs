//! STL models, binary and ASCII, read with `stl_io`: faces only (normals are
//! generated later, as for OBJ). Vertices with the same bits are merged so smooth
//! normals can be shared.

use std::borrow::Cow;
use std::collections::HashMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use glam::Vec3;

use super::{Mesh, MeshError};

/// Bytes of a binary STL header: 80 free bytes and a little-endian triangle count.
const HEADER: usize = 84;
/// Bytes of one binary STL triangle: normal, three vertices, attribute count.
const TRIANGLE: usize = 50;

/// Whether `bytes` are a binary STL by the size rule: 84 + 50·n bytes, n in the header.
#[must_use]
pub fn is_binary_stl(bytes: &[u8]) -> bool {
    declared_triangles(bytes)
        .is_some_and(|n| (HEADER as u64 + TRIANGLE as u64 * n) == bytes.len() as u64)
}

/// Whether `bytes` start like an ASCII STL: `solid`, then a `facet` soon after.
#[must_use]
pub fn is_ascii_stl(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(1024)];
    head.starts_with(b"solid")
        && head.get(5).is_none_or(|c| c.is_ascii_whitespace())
        && (head.windows(5).any(|w| w == b"facet") || head.windows(8).any(|w| w == b"endsolid"))
}

fn declared_triangles(bytes: &[u8]) -> Option<u64> {
    let n = bytes.get(80..HEADER)?;
    Some(u64::from(u32::from_le_bytes([n[0], n[1], n[2], n[3]])))
}

/// Parses an STL file's bytes. Binary if the size rule holds or it does not start
/// like ASCII; a binary file may have bytes after its triangles, not fewer.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let malformed = |line, problem: String| MeshError::Malformed {
        path: path.into(),
        line,
        problem,
    };
    let ascii = !is_binary_stl(bytes) && bytes.starts_with(b"solid");
    if !ascii {
        let Some(n) = declared_triangles(bytes) else {
            return Err(malformed(
                None,
                format!(
                    "binary STL is {} bytes, shorter than its 84-byte header",
                    bytes.len()
                ),
            ));
        };
        let room = (bytes.len() - HEADER) / TRIANGLE;
        if n > room as u64 {
            return Err(malformed(
                None,
                format!(
                    "binary STL declares {n} triangles at byte 80 but has room for {room} (truncated?)"
                ),
            ));
        }
    }
    // stl_io reads ASCII only after `solid ` with a space, and takes any file whose
    // header starts so for ASCII: blank the first byte of a binary header, give a bare
    // `solid` line its space.
    let data: Cow<[u8]> = if ascii && !bytes.starts_with(b"solid ") {
        let mut v = b"solid ".to_vec();
        v.extend_from_slice(&bytes[5..]);
        Cow::Owned(v)
    } else {
        Cow::Borrowed(bytes)
    };
    let read = || -> Result<Mesh, (usize, String)> {
        let mut reader = Slice {
            bytes: &data,
            pos: 0,
            blank_first: !ascii,
        };
        let triangles = stl_io::create_stl_reader(&mut reader).map_err(|e| (0, e.to_string()))?;
        let mut m = Mesh::default();
        let mut seen: HashMap<[u32; 3], u32> = HashMap::new();
        for (k, t) in triangles.enumerate() {
            let t = t.map_err(|e| (k, e.to_string()))?;
            for v in t.vertices {
                let p = Vec3::from_array(v.0);
                if !p.is_finite() {
                    return Err((k, "vertex position is not a finite number".into()));
                }
                let next = m.positions.len() as u32;
                let i = *seen.entry(v.0.map(f32::to_bits)).or_insert(next);
                if i == next {
                    m.positions.push(p);
                }
                m.indices.push(i);
            }
        }
        Ok(m)
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(read))
        .map_err(|_| malformed(None, "the STL reader failed on this file".into()))?;
    let mut m = result.map_err(|(k, problem)| {
        if ascii {
            // Each facet is 7 non-empty lines after the `solid` line.
            malformed(
                nth_nonempty_line(bytes, 1 + 7 * k),
                format!("STL facet {}: {problem}", k + 1),
            )
        } else {
            malformed(
                None,
                format!(
                    "STL triangle {} at byte {}: {problem}",
                    k + 1,
                    HEADER + TRIANGLE * k
                ),
            )
        }
    })?;
    if m.indices.is_empty() {
        return Err(MeshError::Empty {
            path: path.into(),
            note: String::new(),
        });
    }
    m.name = path.display().to_string();
    Ok(m)
}

/// Line number (1-based) of the `n`-th (0-based) non-blank line, or of the last line.
fn nth_nonempty_line(bytes: &[u8], n: usize) -> Option<usize> {
    let mut last = None;
    for (i, (line_no, _)) in bytes
        .split(|&b| b == b'\n')
        .enumerate()
        .filter(|(_, l)| !l.trim_ascii().is_empty())
        .enumerate()
    {
        last = Some(line_no + 1);
        if i == n {
            break;
        }
    }
    last
}

/// A seekable reader over a slice that can show its first byte as 0 (so stl_io does
/// not take a binary header that starts with `solid ` for ASCII).
struct Slice<'a> {
    bytes: &'a [u8],
    pos: usize,
    blank_first: bool,
}

impl Read for Slice<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let rest = self.bytes.get(self.pos..).unwrap_or_default();
        let n = rest.len().min(buf.len());
        buf[..n].copy_from_slice(&rest[..n]);
        if self.blank_first && self.pos == 0 && n > 0 {
            buf[0] = 0;
        }
        self.pos += n;
        Ok(n)
    }
}

impl Seek for Slice<'_> {
    fn seek(&mut self, to: SeekFrom) -> std::io::Result<u64> {
        let len = self.bytes.len() as i64;
        let at = match to {
            SeekFrom::Start(x) => i64::try_from(x).unwrap_or(i64::MAX),
            SeekFrom::End(d) => len.saturating_add(d),
            SeekFrom::Current(d) => (self.pos as i64).saturating_add(d),
        };
        if at < 0 {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "seek before start",
            ));
        }
        self.pos = at.min(len) as usize;
        Ok(self.pos as u64)
    }
}
