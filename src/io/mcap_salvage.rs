//! Finishing an MCAP recording that its writer could not finish: a run killed by SIGKILL or a power loss, or a
//! disk that filled up while the recording was written.
//!
//! The recorder closes its chunk every few seconds ([`crate::io::mcap::McapRecorder::flush_chunk`]), so such a
//! file is a valid MCAP data section up to some record, followed by the start of a record that was never
//! completed. [`salvage`] keeps the complete records (MCAP specification, "Records": each is an opcode byte, a
//! little-endian `u64` length and that many bytes), cuts the file after the last one whose chunks decompress,
//! and ends it with a `DataEnd` record and a `Footer` without a summary section (both allowed by the
//! specification: readers then read the data section linearly, as the official readers do). The file is cut in
//! place, so the salvage needs no free space beyond the 50 bytes of the ending, which the cut itself frees on a
//! full disk. Then, where the disk has room for a copy, the records are written again through the `mcap`
//! crate's writer into a complete file with its summary section (statistics and indexes, so that viewers can
//! seek), which replaces the cut file atomically; without room the cut file stays, valid but unindexed.

use std::fs::OpenOptions;
use std::io::{self, Seek, Write};
use std::path::{Path, PathBuf};

/// The magic bytes that open and close an MCAP file.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";
/// Opcodes of the records a salvage looks at (MCAP specification).
const OP_FOOTER: u8 = 0x02;
const OP_DATA_END: u8 = 0x0F;
/// Opcode byte and length field of every record \[bytes\].
const RECORD_PREFIX: usize = 9;

/// What [`salvage`] found and did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Salvage {
    /// The file was already a complete MCAP file; nothing was changed.
    AlreadyValid {
        /// Its size \[bytes\].
        bytes: u64,
    },
    /// The file was cut after its last complete record and given an ending.
    Finished {
        /// Size before \[bytes\].
        before: u64,
        /// Size after \[bytes\].
        after: u64,
        /// Messages kept (outside and inside chunks).
        messages: usize,
        /// Log time of the last message kept \[ns\].
        last_log_time: Option<u64>,
        /// Whether it was written again with a summary section (statistics and indexes); `false` when the disk
        /// had no room for the copy (the file is valid, read linearly).
        indexed: bool,
    },
}

/// Why a recording cannot be salvaged.
#[derive(Debug, thiserror::Error)]
pub(crate) enum SalvageError {
    /// Reading or cutting the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating-system error.
        source: io::Error,
    },
    /// The file does not start like an MCAP file (or holds not even its header).
    #[error("{path}: not an MCAP recording (no MCAP magic and header at its start)")]
    NotMcap {
        /// The file.
        path: PathBuf,
    },
}

/// Makes the recording at `path` a valid MCAP file, keeping every complete record (see the module docs).
///
/// # Errors
/// [`SalvageError`] when the file cannot be read or cut, or is not an MCAP recording at all.
pub(crate) fn salvage(path: &Path) -> Result<Salvage, SalvageError> {
    let io_err = |source| SalvageError::Io {
        path: path.to_path_buf(),
        source,
    };
    // Opened without following a link (a link in the recording's place points at someone else's file, which a
    // salvage would cut), then read through the handle.
    let mut bytes = Vec::new();
    super::no_follow::open(path, OpenOptions::new().read(true))
        .and_then(|mut f| io::Read::read_to_end(&mut f, &mut bytes))
        .map_err(io_err)?;
    // Read whole once: a complete file is either left alone (indexed) or only re-indexed.
    let complete = if bytes.ends_with(MAGIC) {
        messages_in(&bytes)
    } else {
        None
    };
    if complete.is_some() && has_summary(&bytes) {
        return Ok(Salvage::AlreadyValid {
            bytes: bytes.len() as u64,
        });
    }
    let before = bytes.len() as u64;
    let (content, (messages, last_log_time)) = match complete {
        // Complete but unindexed (an earlier salvage without room for the copy).
        Some(found) => (bytes, found),
        None => cut_in_place(path, &bytes)?,
    };
    let indexed = rewrite_indexed(path, &content).is_ok();
    drop(content);
    let after = std::fs::metadata(path).map_err(io_err)?.len();
    Ok(Salvage::Finished {
        before,
        after,
        messages,
        last_log_time,
        indexed,
    })
}

/// A recording's new content, with its message count and last log time.
type Cut = (Vec<u8>, (usize, Option<u64>));

/// Cuts `bytes` (the content of `path`) after the latest record boundary up to which the file reads whole,
/// and writes the ending there; returns the new content, the messages kept and the last one's log time.
fn cut_in_place(path: &Path, bytes: &[u8]) -> Result<Cut, SalvageError> {
    let io_err = |source| SalvageError::Io {
        path: path.to_path_buf(),
        source,
    };
    // Each candidate keeps the records up to a boundary (the latest first); the first that reads whole wins.
    // The header alone (the first boundary) is the least a recording can be.
    for &cut in record_boundaries(bytes).iter().rev() {
        let mut candidate = bytes[..cut].to_vec();
        candidate.extend_from_slice(&ending());
        if let Some(found) = messages_in(&candidate) {
            let mut file =
                super::no_follow::open(path, OpenOptions::new().write(true)).map_err(io_err)?;
            file.set_len(cut as u64)
                .and_then(|()| {
                    file.seek(io::SeekFrom::End(0))?;
                    file.write_all(&ending())?;
                    file.sync_all()
                })
                .map_err(io_err)?;
            return Ok((candidate, found));
        }
    }
    Err(SalvageError::NotMcap {
        path: path.to_path_buf(),
    })
}

/// Writes the records of the complete (possibly unindexed) recording at `path` again through the `mcap`
/// writer — schemas, channels, messages in file order, attachments, metadata, with the original header's
/// profile and library — into a temporary file renamed over `path` (see [`crate::io::stl`]'s atomic write).
/// `bytes` is the file's content.
fn rewrite_indexed(path: &Path, bytes: &[u8]) -> Result<(), Box<dyn std::error::Error>> {
    use ::mcap::records::Record;
    crate::io::atomic::write_atomically(path, |out| {
        let other = |e: ::mcap::McapError| io::Error::other(e.to_string());
        let mut writer: Option<::mcap::Writer<io::Cursor<Vec<u8>>>> = None;
        for record in ::mcap::read::ChunkFlattener::new(bytes).map_err(other)? {
            let record = record.map_err(other)?;
            if let Record::Header(header) = &record {
                writer = Some(
                    ::mcap::WriteOptions::new()
                        .compression(Some(::mcap::Compression::Zstd))
                        .compression_level(1)
                        .profile(header.profile.clone())
                        .library(header.library.clone())
                        .create(io::Cursor::new(Vec::new()))
                        .map_err(other)?,
                );
                continue;
            }
            let Some(w) = writer.as_mut() else {
                return Err(io::Error::other("records before the header"));
            };
            match record {
                Record::Schema { header, data } => {
                    w.add_schema_with_id(header.id, &header.name, &header.encoding, &data)
                        .map_err(other)?;
                }
                Record::Channel(c) => {
                    w.add_channel_with_id(
                        c.id,
                        c.schema_id,
                        &c.topic,
                        &c.message_encoding,
                        &c.metadata,
                    )
                    .map_err(other)?;
                }
                Record::Message { header, data } => {
                    w.write_to_known_channel(&header, &data).map_err(other)?;
                }
                Record::Attachment { header, data, .. } => {
                    w.attach(&::mcap::Attachment {
                        log_time: header.log_time,
                        create_time: header.create_time,
                        name: header.name,
                        media_type: header.media_type,
                        data,
                    })
                    .map_err(other)?;
                }
                Record::Metadata(m) => w.write_metadata(&m).map_err(other)?,
                // Indexes, statistics and the footer are written anew by the writer.
                _ => {}
            }
        }
        let mut w = writer.ok_or_else(|| io::Error::other("no header"))?;
        w.finish().map_err(other)?;
        out.write_all(w.into_inner().get_ref())
    })?;
    Ok(())
}

/// Whether the footer of a complete file points at a summary section.
fn has_summary(bytes: &[u8]) -> bool {
    // Footer: opcode, length, summary_start (u64) … then the closing magic.
    let footer = bytes.len().saturating_sub(MAGIC.len() + RECORD_PREFIX + 20);
    bytes.get(footer) == Some(&OP_FOOTER)
        && bytes
            .get(footer + RECORD_PREFIX..footer + RECORD_PREFIX + 8)
            .is_some_and(|start| start.iter().any(|&b| b != 0))
}

/// Whether `bytes` is a complete MCAP file that the reference reader reads to its end (the tests' check).
#[cfg(test)]
fn is_valid(bytes: &[u8]) -> bool {
    bytes.len() >= 2 * MAGIC.len() && bytes.ends_with(MAGIC) && messages_in(bytes).is_some()
}

/// Offsets just after each complete data-section record, from the header on: where the file may be cut. Stops
/// at the first record that is incomplete, has an opcode outside the specification's (`0x01..=0x0F`; a
/// zero-filled tail from a power loss has opcode 0), or ends the data section.
fn record_boundaries(bytes: &[u8]) -> Vec<usize> {
    let mut boundaries = Vec::new();
    if !bytes.starts_with(MAGIC) {
        return boundaries;
    }
    let mut offset = MAGIC.len();
    while offset + RECORD_PREFIX <= bytes.len() {
        let opcode = bytes[offset];
        let mut length = [0u8; 8];
        length.copy_from_slice(&bytes[offset + 1..offset + RECORD_PREFIX]);
        let Some(end) = usize::try_from(u64::from_le_bytes(length))
            .ok()
            .and_then(|l| (offset + RECORD_PREFIX).checked_add(l))
        else {
            break;
        };
        if !(0x01..=0x0F).contains(&opcode)
            || opcode == OP_DATA_END
            || opcode == OP_FOOTER
            || end > bytes.len()
        {
            break;
        }
        offset = end;
        boundaries.push(offset);
    }
    boundaries
}

/// A `DataEnd` record (no data-section CRC: 0), a `Footer` pointing at no summary section, and the magic.
fn ending() -> Vec<u8> {
    let mut out = Vec::with_capacity(50);
    out.push(OP_DATA_END);
    out.extend_from_slice(&4u64.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.push(OP_FOOTER);
    out.extend_from_slice(&20u64.to_le_bytes());
    out.extend_from_slice(&0u64.to_le_bytes()); // summary_start
    out.extend_from_slice(&0u64.to_le_bytes()); // summary_offset_start
    out.extend_from_slice(&0u32.to_le_bytes()); // summary_crc
    out.extend_from_slice(MAGIC);
    out
}

/// The number of messages in a complete MCAP file and the last one's log time, read with the `mcap` crate's
/// message stream (which decompresses every chunk and checks the records); `None` when it fails anywhere.
fn messages_in(bytes: &[u8]) -> Option<(usize, Option<u64>)> {
    let stream = ::mcap::MessageStream::new(bytes).ok()?;
    let mut count = 0;
    let mut last = None;
    for message in stream {
        let message = message.ok()?;
        count += 1;
        last = Some(message.log_time);
    }
    // The linear reader also walks the records the message stream skips (metadata, attachments).
    for record in ::mcap::read::LinearReader::new(bytes).ok()? {
        record.ok()?;
    }
    Some((count, last))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// A small recording written with the `mcap` crate: `n` messages on one channel, a chunk closed after every
    /// `per_chunk`.
    fn recording(n: u64, per_chunk: u64) -> Vec<u8> {
        let mut out = io::Cursor::new(Vec::new());
        {
            let mut w = ::mcap::WriteOptions::new()
                .compression(Some(::mcap::Compression::Zstd))
                .create(&mut out)
                .expect("writer");
            let schema = w.add_schema("s", "jsonschema", b"{}").expect("schema");
            let channel = w
                .add_channel(schema, "/t", "json", &BTreeMap::new())
                .expect("channel");
            for i in 0..n {
                w.write_to_known_channel(
                    &::mcap::records::MessageHeader {
                        channel_id: channel,
                        sequence: i as u32,
                        log_time: i * 1000,
                        publish_time: i * 1000,
                    },
                    format!("{{\"i\": {i}, \"pad\": \"{}\"}}", "x".repeat(200)).as_bytes(),
                )
                .expect("message");
                if (i + 1) % per_chunk == 0 {
                    w.flush().expect("chunk");
                }
            }
            w.finish().expect("finish");
        }
        out.into_inner()
    }

    fn scratch(name: &str, bytes: &[u8]) -> PathBuf {
        let path = std::env::temp_dir().join(format!(
            "stentkit-salvage-{name}-{}.mcap",
            std::process::id()
        ));
        std::fs::write(&path, bytes).expect("write");
        path
    }

    #[test]
    fn a_complete_recording_is_left_alone() {
        let bytes = recording(30, 10);
        let path = scratch("complete", &bytes);
        assert_eq!(
            salvage(&path).expect("salvage"),
            Salvage::AlreadyValid {
                bytes: bytes.len() as u64
            }
        );
        assert_eq!(std::fs::read(&path).expect("read"), bytes);
    }

    /// Cut anywhere inside the fourth chunk (as SIGKILL leaves a file), the three closed chunks survive: 30
    /// messages, the last at log time 29 µs. Every cut point inside that chunk is tried.
    #[test]
    fn a_truncated_recording_keeps_its_closed_chunks() {
        let bytes = recording(40, 10);
        let whole = recording(30, 10);
        // The first three chunks end where the 30-message recording's data section ends (same records).
        let chunks_end = record_boundaries(&whole).last().copied().expect("records");
        let data_end = record_boundaries(&bytes)
            .into_iter()
            .find(|&b| b > chunks_end)
            .expect("a fourth chunk");
        for cut in (chunks_end + 1..data_end).step_by(97) {
            let path = scratch("cut", &bytes[..cut]);
            match salvage(&path).expect("salvage") {
                Salvage::Finished {
                    messages,
                    last_log_time,
                    ..
                } => {
                    assert_eq!(messages, 30, "cut at {cut}");
                    assert_eq!(last_log_time, Some(29_000), "cut at {cut}");
                }
                other => panic!("cut at {cut}: {other:?}"),
            }
            let repaired = std::fs::read(&path).expect("read");
            assert!(
                is_valid(&repaired) && has_summary(&repaired),
                "cut at {cut}"
            );
            assert_eq!(messages_in(&repaired), Some((30, Some(29_000))));
        }
    }

    /// A power loss can leave a zero-filled tail; it is cut off like a truncated record.
    #[test]
    fn a_zero_filled_tail_is_cut_off() {
        let mut bytes = recording(20, 10);
        let keep = record_boundaries(&bytes)[3];
        bytes.truncate(keep);
        bytes.extend(std::iter::repeat_n(0u8, 4096));
        let path = scratch("zeros", &bytes);
        assert!(matches!(
            salvage(&path).expect("salvage"),
            Salvage::Finished { .. }
        ));
        assert!(is_valid(&std::fs::read(&path).expect("read")));
    }

    #[test]
    fn a_file_that_is_not_mcap_is_refused() {
        let path = scratch("text", b"time,ux\n0,0\n");
        assert!(matches!(salvage(&path), Err(SalvageError::NotMcap { .. })));
        assert_eq!(std::fs::read(&path).expect("read"), b"time,ux\n0,0\n");
    }
}
