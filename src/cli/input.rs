//! Reading the text files the user names (pose files, reports,
//! detections): UTF-8, or UTF-16 as Windows tools save it (PowerShell's
//! `>` and Notepad's "Unicode"), recognised by its byte order mark or, without
//! one, by the NUL byte beside every ASCII character.

use super::CliError;

/// Read a whole file, with an error that names it.
pub fn read_file(path: &str) -> Result<Vec<u8>, CliError> {
    std::fs::read(path).map_err(|e| CliError::Io(format!("cannot read '{path}': {e}")))
}

/// Read a whole text file (UTF-8 or UTF-16), with an error that names it.
pub fn read_text(path: &str) -> Result<String, CliError> {
    decode_text(read_file(path)?).map_err(|_| {
        CliError::Io(format!(
            "cannot read '{path}': stream did not contain valid UTF-8"
        ))
    })
}

/// [`read_text`] for a pose file, whose error says only that it is not
/// UTF-8 text.
pub fn read_pose_text(path: &str) -> Result<String, CliError> {
    decode_text(read_file(path)?).map_err(|_| CliError::Io(format!("'{path}' is not UTF-8 text")))
}

/// Byte order of a UTF-16 text.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Utf16 {
    Le,
    Be,
}

/// How many leading bytes the NUL-byte test looks at.
const SNIFF_BYTES: usize = 512;

/// The bytes as text: UTF-8 (a leading byte order mark dropped), or UTF-16
/// decoded; `Err` gives the bytes back when they are neither. UTF-16 that
/// does not decode (an unpaired surrogate) is an error that says so.
fn decode_text(bytes: Vec<u8>) -> Result<String, Vec<u8>> {
    let (order, body) = match bytes.as_slice() {
        [0xff, 0xfe, rest @ ..] => (Some(Utf16::Le), rest),
        [0xfe, 0xff, rest @ ..] => (Some(Utf16::Be), rest),
        b => (sniff_utf16(b), b),
    };
    let Some(order) = order else {
        return match String::from_utf8(bytes) {
            Ok(mut text) => {
                if text.starts_with('\u{feff}') {
                    text.drain(..'\u{feff}'.len_utf8());
                }
                Ok(text)
            }
            Err(e) => Err(e.into_bytes()),
        };
    };
    if body.len() % 2 != 0 {
        return Err(bytes);
    }
    let units = body.chunks_exact(2).map(|p| match order {
        Utf16::Le => u16::from_le_bytes([p[0], p[1]]),
        Utf16::Be => u16::from_be_bytes([p[0], p[1]]),
    });
    char::decode_utf16(units)
        .collect::<Result<String, _>>()
        .map_err(|_| bytes.clone())
}

/// UTF-16 without a byte order mark: in the first [`SNIFF_BYTES`] bytes (an
/// even count), at least 90 % of the pairs have a NUL on one side (the
/// high byte of an ASCII character) and none on the other.
fn sniff_utf16(bytes: &[u8]) -> Option<Utf16> {
    let head = &bytes[..bytes.len().min(SNIFF_BYTES)];
    let pairs = head.len() / 2;
    if pairs < 2 || bytes.len() % 2 != 0 {
        return None;
    }
    let count = |nul_at: usize| {
        head.chunks_exact(2)
            .filter(|p| p[nul_at] == 0 && p[1 - nul_at] != 0)
            .count()
    };
    let mostly = |n: usize| n * 10 >= pairs * 9;
    if mostly(count(1)) {
        Some(Utf16::Le)
    } else if mostly(count(0)) {
        Some(Utf16::Be)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn utf16le(text: &str) -> Vec<u8> {
        text.encode_utf16().flat_map(u16::to_le_bytes).collect()
    }

    fn utf16be(text: &str) -> Vec<u8> {
        text.encode_utf16().flat_map(u16::to_be_bytes).collect()
    }

    const POSES: &str = "x,y,z,qx,qy,qz,qw\n0.1,0.2,0.3,0,0,0,1\n";

    #[test]
    fn utf16_with_and_without_a_byte_order_mark_reads_as_its_text() {
        let le_bom = [vec![0xff, 0xfe], utf16le(POSES)].concat();
        let be_bom = [vec![0xfe, 0xff], utf16be(POSES)].concat();
        for bytes in [le_bom, be_bom, utf16le(POSES), utf16be(POSES)] {
            assert_eq!(decode_text(bytes).unwrap(), POSES);
        }
        let utf8_bom = [vec![0xef, 0xbb, 0xbf], POSES.as_bytes().to_vec()].concat();
        assert_eq!(decode_text(utf8_bom).unwrap(), POSES);
        assert_eq!(decode_text(POSES.as_bytes().to_vec()).unwrap(), POSES);
    }

    #[test]
    fn bytes_that_are_neither_utf8_nor_utf16_are_given_back() {
        // A byte order mark and an odd byte: not UTF-16.
        assert_eq!(
            decode_text(b"\xff\xfe\x00".to_vec()).unwrap_err(),
            b"\xff\xfe\x00"
        );
        // An unpaired surrogate.
        let bad = [vec![0xff, 0xfe], vec![0x00, 0xd8, 0x41, 0x00]].concat();
        assert!(decode_text(bad).is_err());
        assert!(decode_text(vec![0xff, 0x41, 0x42]).is_err());
    }
}
