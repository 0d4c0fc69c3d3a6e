//! The bytes behind a glTF document: the GLB container, buffers (the GLB's BIN chunk,
//! `data:` URIs, files next to the model) and accessors read with every offset and
//! length checked, so a bad file is an error naming the JSON path, never a panic.
//!
//! Buffer URIs: `data:` (base64, or percent-encoded) is decoded; a relative path is
//! resolved against the model's folder, and an absolute path or one with `..` is read
//! too (the user could name that file directly), but only as a regular file through
//! [`read_regular`], with all buffer files together within [`model_limit`].
//! Any other scheme (`http:`, `file:`) is refused: the loader never uses the network.

use std::borrow::Cow;
use std::cell::{Cell, OnceCell};
use std::path::{Path, PathBuf};

use base64::Engine;
use gltf::accessor::{DataType, Dimensions};
use gltf::{Accessor, Document, buffer};

use crate::mesh::read::{model_limit, read_regular};

/// Most bytes an accessor without a buffer view (all zeros, then sparse values) may
/// expand to.
const MAX_ZERO_FILLED: usize = 1 << 28;

type Chunk<'a> = (&'a [u8], &'a [u8]);

/// Splits a GLB file into its JSON chunk and its BIN chunk, if any.
pub fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let u32_at = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let version = u32_at(4).ok_or("the GLB header is cut short (12 bytes expected)")?;
    if version != 2 {
        return Err(format!(
            "GLB version {version} (only glTF 2.0 is read; version 1 is obsolete)"
        ));
    }
    let length = u32_at(8).ok_or("the GLB header is cut short (12 bytes expected)")?;
    if length > bytes.len() {
        return Err(format!(
            "the GLB header says {length} bytes, but the file has {}",
            bytes.len()
        ));
    }
    let bytes = &bytes[..length.max(12)];
    // A chunk's type and data, or none at the end of the file.
    let chunk = |at: usize| -> Result<Option<Chunk>, String> {
        if at >= bytes.len() {
            return Ok(None);
        }
        let len = u32_at(at)
            .filter(|_| at + 8 <= bytes.len())
            .ok_or_else(|| format!("byte {at}: a chunk header is cut short (8 bytes expected)"))?;
        let data = bytes.get(at + 8..at + 8 + len).ok_or_else(|| {
            format!(
                "byte {at}: a chunk of {len} bytes goes past the end of the file ({} bytes)",
                bytes.len()
            )
        })?;
        Ok(Some((&bytes[at + 4..at + 8], data)))
    };
    let Some((b"JSON", json)) = chunk(12)? else {
        return Err("byte 12: the first GLB chunk is not JSON".into());
    };
    let next = 20 + json.len().next_multiple_of(4);
    let bin = match chunk(next)? {
        Some((b"BIN\0", data)) => Some(data),
        _ => None,
    };
    Ok((json, bin))
}

/// A URI's scheme (`data`, `http`), if it has one. A single letter is taken as a
/// Windows drive (`C:/models/a.bin`), not a scheme.
pub fn scheme(uri: &str) -> Option<&str> {
    let (s, _) = uri.split_once(':')?;
    let mut chars = s.chars();
    let ok = s.len() > 1
        && chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c));
    ok.then_some(s)
}

/// Decodes `%XX` escapes (`my%20model.bin`).
pub fn percent_decode(s: &str) -> Vec<u8> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = b
            .get(i + 1..i + 3)
            .and_then(|h| std::str::from_utf8(h).ok())
            .and_then(|h| u8::from_str_radix(h, 16).ok());
        match (b[i], hex) {
            (b'%', Some(v)) => {
                out.push(v);
                i += 3;
            }
            (c, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    out
}

/// The bytes of a `data:` URI.
pub fn decode_data_uri(uri: &str) -> Result<Vec<u8>, String> {
    let rest = &uri["data:".len().min(uri.len())..];
    let (header, data) = rest
        .split_once(',')
        .ok_or("a data: URI without a comma before its data")?;
    if header.ends_with(";base64") {
        base64::engine::general_purpose::STANDARD
            .decode(data.trim_end())
            .map_err(|e| format!("the base64 data of a data: URI is broken ({e})"))
    } else {
        Ok(percent_decode(data))
    }
}

/// The path a relative URI names, beside the model file.
pub fn uri_path(dir: &Path, uri: &str) -> PathBuf {
    dir.join(String::from_utf8_lossy(&percent_decode(uri)).as_ref())
}

/// The document's buffers, each resolved the first time an accessor needs it.
pub struct Buffers<'a> {
    doc: &'a Document,
    bin: Option<&'a [u8]>,
    dir: PathBuf,
    slots: Vec<OnceCell<Cow<'a, [u8]>>>,
    read_from_files: Cell<u64>,
}

impl<'a> Buffers<'a> {
    pub fn new(doc: &'a Document, bin: Option<&'a [u8]>, model: &Path) -> Self {
        Self {
            doc,
            bin,
            dir: model.parent().map(Path::to_path_buf).unwrap_or_default(),
            slots: doc.buffers().map(|_| OnceCell::new()).collect(),
            read_from_files: Cell::new(0),
        }
    }

    /// The bytes of buffer `index`, at least its declared `byteLength`.
    pub fn buffer(&self, index: usize) -> Result<&[u8], String> {
        let slot = &self.slots[index];
        if let Some(data) = slot.get() {
            return Ok(data);
        }
        let at = format!("buffers[{index}]");
        let b = self
            .doc
            .buffers()
            .nth(index)
            .ok_or_else(|| format!("{at} does not exist"))?;
        let data: Cow<'a, [u8]> = match b.source() {
            buffer::Source::Bin => {
                Cow::Borrowed(self.bin.ok_or_else(|| {
                    format!("{at} has no uri, and there is no GLB BIN chunk for it")
                })?)
            }
            buffer::Source::Uri(uri) => match scheme(uri) {
                Some("data") => Cow::Owned(decode_data_uri(uri).map_err(|e| format!("{at}: {e}"))?),
                Some(other) => {
                    return Err(format!(
                        "{at}: `{other}:` URIs are not read (only files beside the model and data: URIs)"
                    ));
                }
                None => {
                    let path = uri_path(&self.dir, uri);
                    let limit = model_limit().saturating_sub(self.read_from_files.get());
                    let bytes = read_regular(&path, limit).map_err(|e| format!("{at}: {e}"))?;
                    self.read_from_files
                        .set(self.read_from_files.get() + bytes.len() as u64);
                    Cow::Owned(bytes)
                }
            },
        };
        if data.len() < b.length() {
            return Err(format!(
                "{at}: byteLength is {}, but its data has {} bytes",
                b.length(),
                data.len()
            ));
        }
        let _ = slot.set(data);
        Ok(slot.get().map_or(&[], |d| d))
    }

    /// The bytes of a buffer view.
    pub fn view(&self, view: &buffer::View) -> Result<&[u8], String> {
        let data = self.buffer(view.buffer().index())?;
        let (start, len) = (view.offset(), view.length());
        start
            .checked_add(len)
            .and_then(|end| data.get(start..end))
            .ok_or_else(|| {
                format!(
                    "bufferViews[{}]: bytes {start}..{} are past the end of buffers[{}] ({} bytes)",
                    view.index(),
                    start as u128 + len as u128,
                    view.buffer().index(),
                    data.len()
                )
            })
    }

    /// An accessor's elements, tightly packed, sparse substitutions applied.
    fn packed(&self, acc: &Accessor) -> Result<Vec<u8>, String> {
        let at = format!("accessors[{}]", acc.index());
        let elem = element_size(acc).ok_or_else(|| format!("{at}: matrices are not read"))?;
        let count = acc.count();
        let mut out = match acc.view() {
            None => {
                if count.saturating_mul(elem) > MAX_ZERO_FILLED {
                    return Err(format!(
                        "{at}: {count} elements without a bufferView are more than are read"
                    ));
                }
                vec![0; count * elem]
            }
            Some(view) => {
                let bytes = self.view(&view)?;
                let stride = view.stride().unwrap_or(elem);
                if stride < elem {
                    return Err(format!(
                        "bufferViews[{}]: byteStride {stride} is less than {at}'s {elem}-byte elements",
                        view.index()
                    ));
                }
                let start = acc.offset();
                let end = (count as u128).saturating_sub(1) * stride as u128
                    + (elem as u128) * u128::from(count > 0)
                    + start as u128;
                if end > bytes.len() as u128 {
                    return Err(format!(
                        "{at}: {count} elements from byte {start} (stride {stride}) need {end} bytes, \
                         but bufferViews[{}] has {}",
                        view.index(),
                        bytes.len()
                    ));
                }
                let mut out = Vec::with_capacity(count * elem);
                for i in 0..count {
                    let s = start + i * stride;
                    out.extend_from_slice(&bytes[s..s + elem]);
                }
                out
            }
        };
        if let Some(sparse) = acc.sparse() {
            let n = sparse.count();
            let (iv, vv) = (sparse.indices(), sparse.values());
            let isize = iv.index_type().size();
            let ibytes = slice(self.view(&iv.view())?, iv.offset(), n, isize).ok_or_else(|| {
                format!("{at}.sparse.indices: {n} indices go past their bufferView")
            })?;
            let vbytes = slice(self.view(&vv.view())?, vv.offset(), n, elem).ok_or_else(|| {
                format!("{at}.sparse.values: {n} values go past their bufferView")
            })?;
            for k in 0..n {
                let i = read_uint(&ibytes[k * isize..(k + 1) * isize]) as usize;
                if i >= count {
                    return Err(format!(
                        "{at}.sparse.indices: index {i} is beyond the accessor's {count} elements"
                    ));
                }
                out[i * elem..(i + 1) * elem].copy_from_slice(&vbytes[k * elem..(k + 1) * elem]);
            }
        }
        Ok(out)
    }

    /// An accessor's components as floats (normalised integers mapped to 0..1 or
    /// -1..1 as the glTF specification says), `dims` per element.
    pub fn floats(&self, acc: &Accessor) -> Result<Vec<f32>, String> {
        let packed = self.packed(acc)?;
        let ty = acc.data_type();
        let norm = acc.normalized();
        Ok(packed
            .chunks_exact(ty.size())
            .map(|c| {
                let v = match ty {
                    DataType::F32 => return f32::from_le_bytes([c[0], c[1], c[2], c[3]]),
                    DataType::I8 => f64::from(c[0] as i8),
                    DataType::I16 => f64::from(i16::from_le_bytes([c[0], c[1]])),
                    _ => read_uint(c) as f64,
                };
                if !norm {
                    return v as f32;
                }
                let max = match ty {
                    DataType::I8 => 127.0,
                    DataType::U8 => 255.0,
                    DataType::I16 => 32767.0,
                    DataType::U16 => 65535.0,
                    _ => f64::from(u32::MAX),
                };
                (v / max).max(-1.0) as f32
            })
            .collect())
    }

    /// An accessor of unsigned integers (indices).
    pub fn uints(&self, acc: &Accessor) -> Result<Vec<u32>, String> {
        let ty = acc.data_type();
        if !matches!(ty, DataType::U8 | DataType::U16 | DataType::U32) {
            return Err(format!(
                "accessors[{}]: indices must be unsigned integers, not {ty:?}",
                acc.index()
            ));
        }
        let packed = self.packed(acc)?;
        Ok(packed.chunks_exact(ty.size()).map(read_uint).collect())
    }
}

/// The number of components of an element, for vectors and scalars.
pub fn components(acc: &Accessor) -> Option<usize> {
    match acc.dimensions() {
        Dimensions::Scalar => Some(1),
        Dimensions::Vec2 => Some(2),
        Dimensions::Vec3 => Some(3),
        Dimensions::Vec4 => Some(4),
        _ => None,
    }
}

fn element_size(acc: &Accessor) -> Option<usize> {
    Some(components(acc)? * acc.data_type().size())
}

/// `n` items of `size` bytes from `offset` in `bytes`.
fn slice(bytes: &[u8], offset: usize, n: usize, size: usize) -> Option<&[u8]> {
    let end = offset.checked_add(n.checked_mul(size)?)?;
    bytes.get(offset..end)
}

/// A little-endian unsigned integer of 1, 2 or 4 bytes.
fn read_uint(b: &[u8]) -> u32 {
    b.iter().rev().fold(0, |v, &x| (v << 8) | u32::from(x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schemes_and_paths() {
        assert_eq!(
            scheme("data:application/octet-stream;base64,AAA="),
            Some("data")
        );
        assert_eq!(scheme("https://example.com/a.bin"), Some("https"));
        assert_eq!(scheme("C:/models/a.bin"), None);
        assert_eq!(scheme("a.bin"), None);
        assert_eq!(scheme("sub/x:y.bin"), None);
        assert_eq!(percent_decode("my%20model.bin%2"), b"my model.bin%2");
        assert_eq!(decode_data_uri("data:;base64,AQID").unwrap(), [1, 2, 3]);
        assert_eq!(decode_data_uri("data:,a%41").unwrap(), b"aA");
        assert!(decode_data_uri("data:;base64,@@").is_err());
    }

    #[test]
    fn glb_chunks_are_checked() {
        let mut glb = b"glTF\x02\0\0\0".to_vec();
        glb.extend(24u32.to_le_bytes());
        glb.extend(4u32.to_le_bytes());
        glb.extend(b"JSON{}  ");
        assert_eq!(split_glb(&glb).unwrap(), (&b"{}  "[..], None));
        glb[8] = 200;
        assert!(split_glb(&glb).unwrap_err().contains("200 bytes"));
        glb[8] = 24;
        glb[12] = 9;
        assert!(split_glb(&glb).unwrap_err().contains("byte 12"));
        assert!(split_glb(b"glTF\x01").is_err());
    }
}
