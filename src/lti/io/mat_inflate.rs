//! Bounded decompression of a level-5 MAT-file's compressed elements (`miCOMPRESSED`, zlib),
//! before anything parses them.
//!
//! The `matfile` crate inflates every compressed element whole, with no limit: a 280 kB file of
//! zeros became 288 MB of data (and 1.4 GB at peak) before any dimension check could run. So
//! [`inflate_elements`] rewrites the file first: each `miCOMPRESSED` element is inflated through a
//! reader that stops at [`MAX_MAT_INFLATED_BYTES`] (the total over the file), and the result, an
//! uncompressed file holding the same elements, is what `matfile` parses. A file over the limit
//! is an error before any large allocation.

use std::io::Read;

/// Largest total size of a MAT-file's elements after decompression: 64 MiB, 8 Mi doubles (a dense
/// n = 2 500 plant's A is 6.25 Mi). A plant or controller file holds nothing else worth reading.
pub(crate) const MAX_MAT_INFLATED_BYTES: u64 = 64 << 20;

/// `miCOMPRESSED`: a zlib stream holding one or more data elements.
const MI_COMPRESSED: u32 = 15;

/// The file `bytes` (at least its 128-byte header) with every `miCOMPRESSED` element replaced by
/// the elements it holds, or an error when the elements would exceed `limit` bytes or a
/// compressed stream is damaged (the message; `mat_file` makes it a format error). Elements whose
/// tags run past the end are copied as they are (the parser reports them).
pub(crate) fn inflate_elements(bytes: &[u8], limit: u64) -> Result<Vec<u8>, String> {
    let big_endian = bytes.get(126..128) == Some(b"MI");
    let u32_at = |i: usize| {
        bytes.get(i..i + 4).map(|b| {
            let b = [b[0], b[1], b[2], b[3]];
            if big_endian {
                u32::from_be_bytes(b)
            } else {
                u32::from_le_bytes(b)
            }
        })
    };
    let too_large =
        || format!("its variables hold more than {} MiB once decompressed, the limit for a .mat file", limit >> 20);
    let mut out = bytes[..128.min(bytes.len())].to_vec();
    let mut pos = 128;
    while pos < bytes.len() {
        let (Some(ty), Some(len)) = (u32_at(pos), u32_at(pos + 4)) else { break };
        let len = len as usize;
        let Some(body) = bytes.get(pos + 8..(pos + 8).saturating_add(len)) else { break };
        if ty == MI_COMPRESSED {
            let budget = limit.saturating_sub(out.len() as u64);
            let mut inflated = Vec::new();
            libflate::zlib::Decoder::new(body)
                .and_then(|d| d.take(budget.saturating_add(1)).read_to_end(&mut inflated))
                .map_err(|e| format!("a compressed variable is damaged: {e}"))?;
            if inflated.len() as u64 > budget {
                return Err(too_large());
            }
            out.extend_from_slice(&inflated);
            out.resize(out.len().div_ceil(8) * 8, 0);
            pos += 8 + len;
        } else {
            let end = (pos + 8 + len.div_ceil(8) * 8).min(bytes.len());
            out.extend_from_slice(&bytes[pos..end]);
            pos = end;
        }
        if out.len() as u64 > limit {
            return Err(too_large());
        }
    }
    out.extend_from_slice(&bytes[pos.min(bytes.len())..]);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A little-endian header and one miCOMPRESSED element holding `inner`.
    fn compressed_file(inner: &[u8]) -> Vec<u8> {
        let mut enc = libflate::zlib::Encoder::new(Vec::new()).unwrap();
        std::io::Write::write_all(&mut enc, inner).unwrap();
        let z = enc.finish().into_result().unwrap();
        let mut f = vec![b' '; 126];
        f.extend_from_slice(b"IM");
        f.extend_from_slice(&MI_COMPRESSED.to_le_bytes());
        f.extend_from_slice(&(z.len() as u32).to_le_bytes());
        f.extend_from_slice(&z);
        f
    }

    #[test]
    fn a_zip_bomb_stops_at_the_limit() {
        // 280 kB of compressed zeros expanded to 288 MB before any check.
        let bomb = compressed_file(&vec![0u8; 8 << 20]);
        assert!(bomb.len() < 64 << 10, "{}", bomb.len());
        let e = inflate_elements(&bomb, 1 << 20).unwrap_err();
        assert!(e.to_string().contains("more than 1 MiB once decompressed"), "{e}");
        // the limit counts the whole rewritten file, header included
        assert_eq!(inflate_elements(&bomb, 128 + (8 << 20)).unwrap().len(), 128 + (8 << 20));
    }

    #[test]
    fn damaged_stream_is_a_format_error() {
        let mut f = compressed_file(&[1u8; 100]);
        let n = f.len();
        f[n - 6] ^= 0xff;
        f[136] ^= 0xff; // the zlib header
        assert!(inflate_elements(&f, 1 << 20).unwrap_err().contains("damaged"));
    }
}
