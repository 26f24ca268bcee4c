//! The elements of a `.mat` file, checked whole and inflated under a cap before the `matfile`
//! parser sees them.
//!
//! MATLAB's `-v7` files hold each variable as a zlib-compressed element (`miCOMPRESSED`).
//! The `matfile` crate inflates those whole, with no bound — and inflates a compressed element
//! found inside another one again, so a 250 kB file can ask for gigabytes. It also stops
//! quietly at an element cut short, so a file truncated while copying loses its last variables
//! without a word. This pass walks the file's top-level elements, refuses one that the file
//! ends inside (or whose compressed stream ends early) as truncated, inflates each compressed
//! one through `flate2` — nested ones too — counting every inflated byte against one cap, and
//! hands `matfile` the same file with every element plain (it then inflates nothing). Written
//! here because `matfile` offers neither a limit nor a truncation check.

use std::borrow::Cow;

use flate2::{Decompress, FlushDecompress, Status};

use super::RecordError;
use crate::data::bounded::byte_size;

/// MATLAB's data type of a compressed element.
const MI_COMPRESSED: u32 = 15;
/// Bytes of the file's header.
const HEADER: usize = 128;
/// Compressed elements inside compressed elements that are followed (MATLAB writes none).
const MAX_DEPTH: usize = 4;

/// One element of a `.mat` file (or of an inflated variable).
struct Element<'b> {
    /// Its data type.
    kind: u32,
    /// Where its tag starts.
    start: usize,
    /// Its data.
    body: &'b [u8],
    /// Where the next element starts (past an uncompressed element's padding).
    end: usize,
}

/// What the walk knows of the file: its name, byte order and what is left of the cap.
struct Walk<'s> {
    source: &'s str,
    big_endian: bool,
    file_len: usize,
    limit: u64,
    inflated: u64,
}

/// `bytes` (a level-5 file, header checked) with every compressed element inflated, refusing
/// a file whose compressed elements inflate to more than `limit` bytes in all (counting those
/// nested in others), and a file cut short inside an element. A file without compressed
/// elements is returned as it is.
pub(super) fn inflate<'a>(
    bytes: &'a [u8],
    source: &str,
    limit: u64,
) -> Result<Cow<'a, [u8]>, RecordError> {
    let mut walk = Walk {
        source,
        big_endian: bytes.get(126..128) == Some(b"MI"),
        file_len: bytes.len(),
        limit,
        inflated: 0,
    };
    let body = bytes.get(HEADER..).unwrap_or_default();
    let any_compressed = walk.check(body)?;
    if !any_compressed {
        return Ok(Cow::Borrowed(bytes));
    }
    let mut out = bytes[..HEADER.min(bytes.len())].to_vec();
    walk.flatten(body, None, &mut out, 0)?;
    Ok(Cow::Owned(out))
}

impl Walk<'_> {
    fn word(&self, bytes: &[u8], at: usize) -> Option<u32> {
        let b: [u8; 4] = bytes.get(at..at + 4)?.try_into().ok()?;
        Some(if self.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    /// The elements of `bytes`. An element the bytes end inside is an error; `inside` is the compressed element whose
    /// content `bytes` is, `None` for the file's own elements (after its header).
    fn elements<'b>(
        &self,
        bytes: &'b [u8],
        inside: Option<usize>,
    ) -> Result<Vec<Element<'b>>, RecordError> {
        let mut found = Vec::new();
        let mut at = 0;
        while at < bytes.len() {
            let (Some(tag), Some(size)) = (self.word(bytes, at), self.word(bytes, at + 4)) else {
                return Err(self.truncated(at, 8, bytes.len() - at, inside));
            };
            if tag >> 16 != 0 {
                // The small data element format: type and size in one word, 4 bytes of data.
                found.push(Element {
                    kind: tag & 0xffff,
                    start: at,
                    body: &bytes[at + 4..at + 8],
                    end: at + 8,
                });
                at += 8;
                continue;
            }
            let size = size as usize;
            let Some(body) = bytes.get(at + 8..(at + 8).saturating_add(size)) else {
                return Err(self.truncated(at, size + 8, bytes.len() - at, inside));
            };
            let end = if tag == MI_COMPRESSED {
                at + 8 + size
            } else {
                (at + 8 + size).next_multiple_of(8).min(bytes.len())
            };
            found.push(Element {
                kind: tag,
                start: at,
                body,
                end,
            });
            at = end;
        }
        Ok(found)
    }

    /// Check the top-level elements are whole; whether any is compressed.
    fn check(&self, bytes: &[u8]) -> Result<bool, RecordError> {
        let elements = self.elements(bytes, None)?;
        Ok(elements.iter().any(|e| e.kind == MI_COMPRESSED))
    }

    /// Append the elements of `bytes` to `out`, each compressed one inflated (and the
    /// compressed ones its content holds, to `MAX_DEPTH`), each padded to 8 bytes as
    /// `matfile` expects. `inside` as for [`Self::elements`].
    fn flatten(
        &mut self,
        bytes: &[u8],
        inside: Option<usize>,
        out: &mut Vec<u8>,
        depth: usize,
    ) -> Result<(), RecordError> {
        for Element {
            kind,
            start: at,
            body,
            end,
        } in self.elements(bytes, inside)?
        {
            // Where the element is in the file: nested content is placed at its outer element.
            let place = inside.unwrap_or(HEADER + at);
            if kind != MI_COMPRESSED {
                out.extend_from_slice(&bytes[at..end]);
            } else if depth >= MAX_DEPTH {
                return Err(RecordError::new(
                    self.source,
                    format!(
                        "the compressed variable at byte {} is compressed {} times over; \
                         MATLAB compresses a variable once: this is not a file MATLAB wrote",
                        place,
                        depth + 1
                    ),
                ));
            } else {
                let inner = self.inflate_one(body, place)?;
                self.flatten(&inner, Some(place), out, depth + 1)?;
            }
            out.resize(out.len().next_multiple_of(8), 0);
        }
        Ok(())
    }

    /// The content of one compressed element, refused past what is left of the cap or when
    /// its stream ends before its end marker.
    fn inflate_one(&mut self, body: &[u8], at: usize) -> Result<Vec<u8>, RecordError> {
        let budget = self.limit.saturating_sub(self.inflated);
        let mut d = Decompress::new(true);
        let mut out: Vec<u8> = Vec::new();
        loop {
            if out.len() as u64 > budget {
                return Err(self.over_cap());
            }
            let room = (budget + 1 - out.len() as u64).min(1 << 20) as usize;
            out.reserve(room);
            let (before_in, before_out) = (d.total_in(), d.total_out());
            let input = body.get(before_in as usize..).unwrap_or_default();
            let status = d
                .decompress_vec(input, &mut out, FlushDecompress::None)
                .map_err(|e| {
                    RecordError::new(
                        self.source,
                        format!("cannot inflate the compressed variable at byte {at}: {e}"),
                    )
                })?;
            if status == Status::StreamEnd {
                break;
            }
            if d.total_in() == before_in && d.total_out() == before_out {
                return Err(RecordError::new(
                    self.source,
                    format!(
                        "is truncated: the compressed variable at byte {at} ends before its \
                         stream does (was the file cut short while copying?)"
                    ),
                ));
            }
        }
        self.inflated += out.len() as u64;
        if self.inflated > self.limit {
            return Err(self.over_cap());
        }
        Ok(out)
    }

    fn over_cap(&self) -> RecordError {
        RecordError::new(
            self.source,
            format!(
                "its compressed variables inflate to more than the limit of {} for a record \
                 (`max_bytes`; the file itself is {})",
                byte_size(self.limit),
                byte_size(self.file_len as u64)
            ),
        )
    }

    /// An element at `at` of its bytes that needs `wanted` bytes where `left` remain: in
    /// the file itself or `inside` an inflated variable.
    fn truncated(
        &self,
        at: usize,
        wanted: usize,
        left: usize,
        inside: Option<usize>,
    ) -> RecordError {
        let message = match inside {
            None => format!(
                "is truncated: the variable at byte {} needs {wanted} bytes but the file \
                 ends {left} bytes later (was it cut short while copying?)",
                HEADER + at
            ),
            Some(outer) => format!(
                "is truncated: the compressed variable at byte {outer} inflates to an \
                 element that needs {wanted} bytes where {left} are left"
            ),
        };
        RecordError::new(self.source, message)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::super::mat::tests::{col, compressed, mat_v5};
    use super::super::ReadOptions;
    use flate2::{Compress, Compression, FlushCompress};

    /// A zlib stream of `prefix` followed by `zeros` zero bytes, built without compressing
    /// them all: after a sync flush, each further MiB of zeros compresses to the same bytes, so
    /// the stream repeats those and ends with an empty final block and the Adler-32 of the
    /// whole. Gigabytes of zeros cost milliseconds.
    pub fn zlib_of_zeros(prefix: &[u8], zeros: u64) -> Vec<u8> {
        const CHUNK: usize = 1 << 20;
        let chunk = vec![0u8; CHUNK];
        let mut c = Compress::new(Compression::best(), true);
        let mut out = Vec::with_capacity(1 << 16);
        let flush = |c: &mut Compress, input: &[u8], out: &mut Vec<u8>| {
            let start = out.len();
            let mut fed = 0;
            loop {
                out.reserve(1 << 16);
                let before = c.total_in();
                c.compress_vec(&input[fed..], out, FlushCompress::Sync)
                    .unwrap();
                fed += (c.total_in() - before) as usize;
                if fed == input.len() && out.len() < out.capacity() {
                    return out[start..].to_vec();
                }
            }
        };
        flush(&mut c, prefix, &mut out);
        let full = zeros / CHUNK as u64;
        let mut parts: Vec<Vec<u8>> = Vec::new();
        for _ in 0..full.min(3) {
            parts.push(flush(&mut c, &chunk, &mut out));
        }
        if full > 3 {
            assert_eq!(parts[1], parts[2], "the repeated block is not stable");
            for _ in 3..full {
                out.extend_from_slice(&parts[2]);
            }
        }
        let rest = (zeros % CHUNK as u64) as usize;
        flush(&mut c, &chunk[..rest], &mut out);
        out.extend_from_slice(&[0x03, 0x00]); // an empty final block (fixed Huffman)
        let (mut a, mut b) = (1u64, 0u64);
        for &byte in prefix {
            a = (a + u64::from(byte)) % 65521;
            b = (b + a) % 65521;
        }
        b = (b + a * (zeros % 65521)) % 65521;
        out.extend_from_slice(&((b << 16 | a) as u32).to_be_bytes());
        out
    }

    /// A `.mat` file whose one compressed element inflates to another compressed element,
    /// which inflates to a matrix element of `zeros` zero bytes: the nested zlib bomb.
    pub fn nested_bomb(zeros: u32) -> Vec<u8> {
        let mut innermost = 14u32.to_le_bytes().to_vec(); // miMATRIX
        innermost.extend_from_slice(&zeros.to_le_bytes());
        let stream = zlib_of_zeros(&innermost, u64::from(zeros));
        let mut middle = 15u32.to_le_bytes().to_vec();
        middle.extend_from_slice(&(stream.len() as u32).to_le_bytes());
        middle.extend_from_slice(&stream);
        let mut out = mat_v5(&[]);
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), Compression::best());
        std::io::Write::write_all(&mut z, &middle).unwrap();
        let z = z.finish().unwrap();
        out.extend_from_slice(&15u32.to_le_bytes());
        out.extend_from_slice(&(z.len() as u32).to_le_bytes());
        out.extend_from_slice(&z);
        out
    }

    #[test]
    fn the_zeros_generator_inflates_to_what_it_says() {
        use std::io::Read;
        for zeros in [0, 5, (3 << 20) + 17, 5 << 20] {
            let stream = zlib_of_zeros(b"head", zeros);
            let mut back = Vec::new();
            flate2::read::ZlibDecoder::new(&stream[..])
                .read_to_end(&mut back)
                .unwrap();
            assert_eq!(back.len() as u64, 4 + zeros);
            assert_eq!(&back[..4], b"head");
            assert!(back[4..].iter().all(|&b| b == 0));
            // The checksum is right: a strict inflater reaches the stream's end.
            let mut d = flate2::Decompress::new(true);
            let mut sink = Vec::with_capacity(back.len() + 1);
            let status = d
                .decompress_vec(&stream, &mut sink, flate2::FlushDecompress::Finish)
                .unwrap();
            assert_eq!(status, flate2::Status::StreamEnd);
        }
    }

    #[test]
    fn a_nested_zlib_bomb_is_stopped_at_the_record_cap() {
        // 3 GiB of zeros, compressed twice: the file is a few hundred kB.
        let bomb = nested_bomb(3 << 30);
        assert!(bomb.len() < 1_000_000, "{}", bomb.len());
        let e = ReadOptions::default()
            .read_mat_bytes(&bomb, "nested.mat")
            .unwrap_err();
        assert_eq!(e.file, "nested.mat");
        assert!(
            e.message.starts_with(
                "its compressed variables inflate to more than the limit of 1073741824 bytes \
                 (1073.7 MB) for a record (`max_bytes`"
            ),
            "{e}"
        );
        // Under a smaller cap, the same, sooner.
        let e = ReadOptions::default()
            .max_bytes(4_000_000)
            .read_mat_bytes(&bomb, "nested.mat")
            .unwrap_err();
        assert!(e.message.contains("limit of 4000000 bytes"), "{e}");
    }

    #[test]
    fn compression_nested_past_any_use_is_refused() {
        let mut element = mat_v5(&[col("t", &[0.0, 1.0], true)])[128..].to_vec();
        for _ in 0..6 {
            let z = zlib_of_zeros(&element, 0);
            element = 15u32.to_le_bytes().to_vec();
            element.extend_from_slice(&(z.len() as u32).to_le_bytes());
            element.extend_from_slice(&z);
        }
        let mut file = mat_v5(&[]);
        file.extend_from_slice(&element);
        let e = ReadOptions::default()
            .read_mat_bytes(&file, "deep.mat")
            .unwrap_err();
        assert!(e.message.contains("compressed 5 times over"), "{e}");
    }

    /// A record of `n` samples with a force column, plain and compressed.
    fn record_files(n: usize) -> [Vec<u8>; 2] {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = t.iter().map(|t| 1e-3 * (7.0 * t).sin()).collect();
        let phi: Vec<f64> = t.iter().map(|t| 6.0 * t).collect();
        let f: Vec<f64> = t.iter().map(|t| 0.1 * (7.0 * t).cos()).collect();
        let plain = mat_v5(&[
            col("t", &t, true),
            col("x", &x, true),
            col("phi", &phi, true),
            col("f_stf", &f, true),
        ]);
        let packed = compressed(&plain);
        [plain, packed]
    }

    #[test]
    fn a_file_cut_short_says_truncated_instead_of_dropping_variables() {
        for bytes in record_files(2000) {
            let whole = ReadOptions::default()
                .read_mat_bytes(&bytes, "r.mat")
                .unwrap();
            assert!(whole.f_stf.is_some());
            for keep in [0.999, 0.5, 0.1] {
                let cut = &bytes[..(bytes.len() as f64 * keep) as usize];
                let e = ReadOptions::default()
                    .read_mat_bytes(cut, "cut.mat")
                    .unwrap_err();
                assert_eq!(e.file, "cut.mat");
                assert!(e.message.starts_with("is truncated: "), "{keep}: {e}");
            }
            // Cut inside the last tag, or by the checksum alone.
            for drop in [1, 4, 7] {
                let e = ReadOptions::default()
                    .read_mat_bytes(&bytes[..bytes.len() - drop], "cut.mat")
                    .unwrap_err();
                assert!(e.message.contains("truncated"), "{drop}: {e}");
            }
        }
    }
}
