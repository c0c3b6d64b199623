//! OpenCV's predefined marker dictionaries (ArUco, AprilTag, ArUco MIP) as
//! data, and decoding of a sampled bit grid to a marker id.
//!
//! The bit tables are `dictionaries.txt` beside this file, generated from
//! OpenCV by `tools/gen_marker_dictionaries.py` (provenance and licence in
//! its header) and parsed once on first use. A marker's bits are read
//! row-major from its top-left bit as printed, 1 = white, the first bit the
//! most significant of a `u64` (at most 7 x 7 = 49 bits).

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// The generated tables (see the module docs).
const TABLES_TEXT: &str = include_str!("dictionaries.txt");

/// One of OpenCV's predefined dictionaries, named exactly as OpenCV names it
/// (`cv::aruco::PredefinedDictionaryType`); in JSON and specs the same name.
#[allow(non_camel_case_types)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Dictionary {
    /// 50 markers of 4 x 4 bits.
    DICT_4X4_50,
    /// 100 markers of 4 x 4 bits.
    DICT_4X4_100,
    /// 250 markers of 4 x 4 bits.
    DICT_4X4_250,
    /// 1000 markers of 4 x 4 bits.
    DICT_4X4_1000,
    /// 50 markers of 5 x 5 bits.
    DICT_5X5_50,
    /// 100 markers of 5 x 5 bits.
    DICT_5X5_100,
    /// 250 markers of 5 x 5 bits.
    DICT_5X5_250,
    /// 1000 markers of 5 x 5 bits.
    DICT_5X5_1000,
    /// 50 markers of 6 x 6 bits.
    DICT_6X6_50,
    /// 100 markers of 6 x 6 bits.
    DICT_6X6_100,
    /// 250 markers of 6 x 6 bits.
    DICT_6X6_250,
    /// 1000 markers of 6 x 6 bits.
    DICT_6X6_1000,
    /// 50 markers of 7 x 7 bits.
    DICT_7X7_50,
    /// 100 markers of 7 x 7 bits.
    DICT_7X7_100,
    /// 250 markers of 7 x 7 bits.
    DICT_7X7_250,
    /// 1000 markers of 7 x 7 bits.
    DICT_7X7_1000,
    /// The original ArUco library's 1024 markers of 5 x 5 bits.
    DICT_ARUCO_ORIGINAL,
    /// AprilTag 16h5: 30 markers of 4 x 4 bits.
    DICT_APRILTAG_16h5,
    /// AprilTag 25h9: 35 markers of 5 x 5 bits.
    DICT_APRILTAG_25h9,
    /// AprilTag 36h10: 2320 markers of 6 x 6 bits.
    DICT_APRILTAG_36h10,
    /// AprilTag 36h11: 587 markers of 6 x 6 bits (Kalibr's AprilGrid).
    DICT_APRILTAG_36h11,
    /// ArUco MIP 36h12: 250 markers of 6 x 6 bits.
    DICT_ARUCO_MIP_36h12,
}

/// A decoded marker: which one, how it lies in the sampled grid, how many
/// bits were wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Decoded {
    /// Marker id in the dictionary.
    pub id: usize,
    /// The sampled grid is the marker turned clockwise this many quarter
    /// turns (0..=3): the marker's own top-left corner is the sampled grid's
    /// corner `rotation` in clockwise order (0 top-left, 1 top-right, ...).
    pub rotation: usize,
    /// Bits that differ from the marker (Hamming distance).
    pub bit_errors: u32,
}

/// One parsed dictionary: bits per side, OpenCV's correction limit and every
/// marker's code in its four rotations.
#[derive(Debug)]
struct Table {
    size: usize,
    max_correction_bits: u32,
    /// `rotations[id][k]`: the code turned clockwise `k` quarter turns.
    rotations: Vec<[u64; 4]>,
}

impl Dictionary {
    /// Every predefined dictionary in OpenCV's enum order.
    pub const ALL: [Dictionary; 22] = [
        Dictionary::DICT_4X4_50,
        Dictionary::DICT_4X4_100,
        Dictionary::DICT_4X4_250,
        Dictionary::DICT_4X4_1000,
        Dictionary::DICT_5X5_50,
        Dictionary::DICT_5X5_100,
        Dictionary::DICT_5X5_250,
        Dictionary::DICT_5X5_1000,
        Dictionary::DICT_6X6_50,
        Dictionary::DICT_6X6_100,
        Dictionary::DICT_6X6_250,
        Dictionary::DICT_6X6_1000,
        Dictionary::DICT_7X7_50,
        Dictionary::DICT_7X7_100,
        Dictionary::DICT_7X7_250,
        Dictionary::DICT_7X7_1000,
        Dictionary::DICT_ARUCO_ORIGINAL,
        Dictionary::DICT_APRILTAG_16h5,
        Dictionary::DICT_APRILTAG_25h9,
        Dictionary::DICT_APRILTAG_36h10,
        Dictionary::DICT_APRILTAG_36h11,
        Dictionary::DICT_ARUCO_MIP_36h12,
    ];

    /// OpenCV's name, e.g. `DICT_5X5_100`.
    pub fn name(self) -> &'static str {
        match self {
            Dictionary::DICT_4X4_50 => "DICT_4X4_50",
            Dictionary::DICT_4X4_100 => "DICT_4X4_100",
            Dictionary::DICT_4X4_250 => "DICT_4X4_250",
            Dictionary::DICT_4X4_1000 => "DICT_4X4_1000",
            Dictionary::DICT_5X5_50 => "DICT_5X5_50",
            Dictionary::DICT_5X5_100 => "DICT_5X5_100",
            Dictionary::DICT_5X5_250 => "DICT_5X5_250",
            Dictionary::DICT_5X5_1000 => "DICT_5X5_1000",
            Dictionary::DICT_6X6_50 => "DICT_6X6_50",
            Dictionary::DICT_6X6_100 => "DICT_6X6_100",
            Dictionary::DICT_6X6_250 => "DICT_6X6_250",
            Dictionary::DICT_6X6_1000 => "DICT_6X6_1000",
            Dictionary::DICT_7X7_50 => "DICT_7X7_50",
            Dictionary::DICT_7X7_100 => "DICT_7X7_100",
            Dictionary::DICT_7X7_250 => "DICT_7X7_250",
            Dictionary::DICT_7X7_1000 => "DICT_7X7_1000",
            Dictionary::DICT_ARUCO_ORIGINAL => "DICT_ARUCO_ORIGINAL",
            Dictionary::DICT_APRILTAG_16h5 => "DICT_APRILTAG_16h5",
            Dictionary::DICT_APRILTAG_25h9 => "DICT_APRILTAG_25h9",
            Dictionary::DICT_APRILTAG_36h10 => "DICT_APRILTAG_36h10",
            Dictionary::DICT_APRILTAG_36h11 => "DICT_APRILTAG_36h11",
            Dictionary::DICT_ARUCO_MIP_36h12 => "DICT_ARUCO_MIP_36h12",
        }
    }

    /// The dictionary named `name`, case-insensitively (OpenCV's Python
    /// bindings also accept `DICT_APRILTAG_36H11`); the error lists every
    /// known name.
    pub fn from_name(name: &str) -> Result<Dictionary> {
        Dictionary::ALL
            .into_iter()
            .find(|d| d.name().eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                let known: Vec<&str> = Dictionary::ALL.iter().map(|d| d.name()).collect();
                Error::invalid(
                    "target",
                    format!(
                        "unknown marker dictionary '{name}'; known: {}",
                        known.join(", ")
                    ),
                )
            })
    }

    fn table(self) -> &'static Table {
        let index = Dictionary::ALL
            .iter()
            .position(|d| *d == self)
            .unwrap_or_default();
        &tables()[index]
    }

    /// Bits per marker side (4 to 7), without the black border.
    pub fn marker_bits(self) -> usize {
        self.table().size
    }

    /// Number of markers.
    pub fn len(self) -> usize {
        self.table().rotations.len()
    }

    /// Always false: every predefined dictionary has markers.
    pub fn is_empty(self) -> bool {
        self.table().rotations.is_empty()
    }

    /// OpenCV's `maxCorrectionBits`: the most wrong bits a read may have and
    /// still decode to the nearest marker unambiguously.
    pub fn max_correction_bits(self) -> u32 {
        self.table().max_correction_bits
    }

    /// Marker `id`'s bits at rotation 0 (see the module docs), `None` past
    /// the end.
    pub fn code(self, id: usize) -> Option<u64> {
        self.table().rotations.get(id).map(|r| r[0])
    }

    /// The nearest marker to a sampled `bits` grid (row-major, first bit the
    /// most significant) in any of its four rotations, when at most
    /// `max_bit_errors` bits differ. Ties go to the lower id.
    pub fn decode(self, bits: u64, max_bit_errors: u32) -> Option<Decoded> {
        let mut best: Option<Decoded> = None;
        for (id, rotations) in self.table().rotations.iter().enumerate() {
            for (rotation, code) in rotations.iter().enumerate() {
                let bit_errors = (bits ^ code).count_ones();
                if bit_errors <= max_bit_errors && best.map_or(true, |b| bit_errors < b.bit_errors)
                {
                    best = Some(Decoded {
                        id,
                        rotation,
                        bit_errors,
                    });
                }
            }
        }
        best
    }
}

/// A code turned clockwise a quarter turn: bit (r, c) of the result is bit
/// (n - 1 - c, r) of `code`.
pub fn rotate_clockwise(code: u64, n: usize) -> u64 {
    let bit = |r: usize, c: usize| (code >> (n * n - 1 - (r * n + c))) & 1;
    let mut out = 0;
    for r in 0..n {
        for c in 0..n {
            out = (out << 1) | bit(n - 1 - c, r);
        }
    }
    out
}

/// Every dictionary's table in [`Dictionary::ALL`] order, parsed once.
fn tables() -> &'static [Table] {
    static TABLES: OnceLock<Vec<Table>> = OnceLock::new();
    TABLES.get_or_init(|| {
        // The text is compiled in and checked by the tests (every dictionary
        // present, with OpenCV's counts): a failure here is a build defect.
        parse_tables(TABLES_TEXT).unwrap_or_else(|e| panic!("dictionaries.txt: {e}"))
    })
}

/// Parse the data file (format in its header).
fn parse_tables(text: &str) -> std::result::Result<Vec<Table>, String> {
    struct DictLine<'a> {
        name: &'a str,
        size: usize,
        correction: u32,
        table: &'a str,
        count: usize,
    }
    let mut dicts = Vec::new();
    let mut codes: Vec<(&str, usize, Vec<u64>)> = Vec::new();
    let num = |s: &str, line: usize| {
        s.parse::<usize>()
            .map_err(|_| format!("line {line}: '{s}' is not a count"))
    };
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let fields: Vec<&str> = line.split_whitespace().collect();
        match fields.as_slice() {
            [] => {}
            ["dict", name, size, correction, table, count] => dicts.push(DictLine {
                name,
                size: num(size, i + 1)?,
                correction: num(correction, i + 1)? as u32,
                table,
                count: num(count, i + 1)?,
            }),
            ["table", name, size, _count] => codes.push((name, num(size, i + 1)?, Vec::new())),
            hex => {
                let (_, _, list) = codes
                    .last_mut()
                    .ok_or_else(|| format!("line {}: codes before any table", i + 1))?;
                for h in hex {
                    list.push(
                        u64::from_str_radix(h, 16)
                            .map_err(|_| format!("line {}: '{h}' is not hexadecimal", i + 1))?,
                    );
                }
            }
        }
    }
    Dictionary::ALL
        .iter()
        .map(|d| {
            let line = dicts
                .iter()
                .find(|l| l.name == d.name())
                .ok_or_else(|| format!("{} missing", d.name()))?;
            let (_, size, list) = codes
                .iter()
                .find(|(name, size, _)| *name == line.table && *size == line.size)
                .ok_or_else(|| format!("table {} missing", line.table))?;
            let list = list
                .get(..line.count)
                .ok_or_else(|| format!("table {} shorter than {}", line.table, line.count))?;
            let rotations = list
                .iter()
                .map(|&c| {
                    let r1 = rotate_clockwise(c, *size);
                    let r2 = rotate_clockwise(r1, *size);
                    [c, r1, r2, rotate_clockwise(r2, *size)]
                })
                .collect();
            Ok(Table {
                size: *size,
                max_correction_bits: line.correction,
                rotations,
            })
        })
        .collect()
}

#[cfg(test)]
#[path = "dictionary_tests.rs"]
mod tests;
