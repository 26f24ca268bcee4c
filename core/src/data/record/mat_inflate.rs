//! The compressed variables of a `.mat` file, inflated under a cap before the `matfile`
//! parser sees them.
//!
//! MATLAB's `-v7` files hold each variable as a zlib-compressed element (`miCOMPRESSED`).
//! The `matfile` crate inflates those whole, with no bound, so a 2 MB file can ask for
//! gigabytes. This pass walks the file's top-level elements, inflates each compressed one
//! through `flate2` reading at most the bytes left under the cap, and hands `matfile` the same
//! file with those elements already inflated (it then inflates nothing). Written here because
//! `matfile` offers no limit of its own.

use std::borrow::Cow;
use std::io::Read;

use super::RecordError;
use crate::data::bounded::byte_size;

/// MATLAB's data type of a compressed element.
const MI_COMPRESSED: u32 = 15;
/// Bytes of the file's header.
const HEADER: usize = 128;

/// `bytes` (a level-5 file, header checked) with every compressed element inflated, refusing
/// a file whose compressed elements inflate to more than `limit` bytes in all. A file without
/// compressed elements is returned as it is.
pub(super) fn inflate<'a>(
    bytes: &'a [u8],
    source: &str,
    limit: u64,
) -> Result<Cow<'a, [u8]>, RecordError> {
    let big_endian = bytes.get(126..128) == Some(b"MI");
    let word = |at: usize| -> Option<u32> {
        let b: [u8; 4] = bytes.get(at..at + 4)?.try_into().ok()?;
        Some(if big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    };
    let mut out: Option<Vec<u8>> = None;
    let mut inflated_total: u64 = 0;
    let mut at = HEADER;
    while let (Some(kind), Some(size)) = (word(at), word(at + 4)) {
        let size = size as usize;
        let Some(body) = bytes.get(at + 8..(at + 8).saturating_add(size)) else {
            break; // a truncated element: the parser says what is wrong
        };
        let next = if kind == MI_COMPRESSED {
            at + 8 + size
        } else {
            (at + 8 + size).next_multiple_of(8).min(bytes.len())
        };
        if kind == MI_COMPRESSED {
            let buf = out.get_or_insert_with(|| bytes[..at].to_vec());
            let budget = limit.saturating_sub(inflated_total);
            let before = buf.len();
            flate2::read::ZlibDecoder::new(body)
                .take(budget.saturating_add(1))
                .read_to_end(buf)
                .map_err(|e| {
                    RecordError::new(
                        source,
                        format!("cannot inflate the compressed variable at byte {at}: {e}"),
                    )
                })?;
            inflated_total += (buf.len() - before) as u64;
            // `matfile` steps over an element's padding to 8 bytes: give it some.
            buf.resize(before + (buf.len() - before).next_multiple_of(8), 0);
            if inflated_total > limit {
                return Err(RecordError::new(
                    source,
                    format!(
                        "its compressed variables inflate to more than the limit of {} for a \
                         record (`max_bytes`; the file itself is {})",
                        byte_size(limit),
                        byte_size(bytes.len() as u64)
                    ),
                ));
            }
        } else if let Some(buf) = out.as_mut() {
            buf.extend_from_slice(&bytes[at..next]);
        }
        at = next;
    }
    Ok(match out {
        Some(mut buf) => {
            buf.extend_from_slice(bytes.get(at..).unwrap_or_default());
            Cow::Owned(buf)
        }
        None => Cow::Borrowed(bytes),
    })
}
