//! CRC-32/ISO-HDLC (the checksum of PNG chunks, zlib's `crc32`, Ethernet):
//! reflected polynomial 0xEDB88320, initial value and final XOR 0xFFFFFFFF.
//!
//! robocal's stand-in for the crates.io `crc32fast` (patched in by the
//! workspace): the same `Hasher` / `hash` API, computed slice-by-8 with
//! tables built once at first use instead of stored in the binary.
#![deny(missing_docs)]

use std::sync::OnceLock;

const POLY: u32 = 0xEDB8_8320;

/// `TABLES[k][b]`: the CRC of byte `b` followed by `k` zero bytes.
fn tables() -> &'static [[u32; 256]; 8] {
    static TABLES: OnceLock<Box<[[u32; 256]; 8]>> = OnceLock::new();
    TABLES.get_or_init(|| {
        let mut t = Box::new([[0u32; 256]; 8]);
        for b in 0..256u32 {
            let mut c = b;
            for _ in 0..8 {
                c = if c & 1 != 0 { POLY ^ (c >> 1) } else { c >> 1 };
            }
            t[0][b as usize] = c;
        }
        for k in 1..8 {
            for b in 0..256 {
                let prev = t[k - 1][b];
                t[k][b] = (prev >> 8) ^ t[0][(prev & 0xFF) as usize];
            }
        }
        t
    })
}

/// Advances the raw (not inverted) register `crc` over `data`.
fn advance(mut crc: u32, data: &[u8]) -> u32 {
    let t = tables();
    let mut chunks = data.chunks_exact(8);
    for c in &mut chunks {
        let lo = crc ^ u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        let hi = u32::from_le_bytes([c[4], c[5], c[6], c[7]]);
        crc = t[7][(lo & 0xFF) as usize]
            ^ t[6][((lo >> 8) & 0xFF) as usize]
            ^ t[5][((lo >> 16) & 0xFF) as usize]
            ^ t[4][(lo >> 24) as usize]
            ^ t[3][(hi & 0xFF) as usize]
            ^ t[2][((hi >> 8) & 0xFF) as usize]
            ^ t[1][((hi >> 16) & 0xFF) as usize]
            ^ t[0][(hi >> 24) as usize];
    }
    for &b in chunks.remainder() {
        crc = t[0][((crc ^ b as u32) & 0xFF) as usize] ^ (crc >> 8);
    }
    crc
}

/// `mat` (a 32x32 matrix over GF(2), one u32 per column) times `vec`.
fn gf2_times(mat: &[u32; 32], mut vec: u32) -> u32 {
    let mut sum = 0;
    let mut i = 0;
    while vec != 0 {
        if vec & 1 != 0 {
            sum ^= mat[i];
        }
        vec >>= 1;
        i += 1;
    }
    sum
}

fn gf2_square(mat: &[u32; 32]) -> [u32; 32] {
    let mut sq = [0u32; 32];
    for (n, col) in sq.iter_mut().enumerate() {
        *col = gf2_times(mat, mat[n]);
    }
    sq
}

/// The finalized CRC `crc` of some bytes, carried over `len` zero bytes with
/// no initial value or final XOR: `crc(A ++ B) = zeros(crc(A), |B|) ^ crc(B)`
/// (the register is linear in its state). The operator for one zero bit is
/// squared up to one byte and then applied per set bit of `len`.
fn shift_over_zeros(mut crc: u32, mut len: u64) -> u32 {
    let mut op = [0u32; 32];
    op[0] = POLY;
    for (n, col) in op.iter_mut().enumerate().skip(1) {
        *col = 1 << (n - 1);
    }
    op = gf2_square(&op); // 2 zero bits
    op = gf2_square(&op); // 4 zero bits
    while len != 0 {
        op = gf2_square(&op); // 8, 16, 32, ... zero bits: one byte, two, four, ...
        if len & 1 != 0 {
            crc = gf2_times(&op, crc);
        }
        len >>= 1;
    }
    crc
}

/// A running CRC-32 over the bytes given to [`Hasher::update`].
#[derive(Clone, Debug)]
pub struct Hasher {
    state: u32,
    amount: u64,
}

impl Default for Hasher {
    fn default() -> Self {
        Hasher::new()
    }
}

impl Hasher {
    /// A hasher over no bytes yet.
    pub fn new() -> Hasher {
        Hasher::new_with_initial(0)
    }

    /// A hasher that continues from `init`, the finalized CRC of earlier bytes.
    pub fn new_with_initial(init: u32) -> Hasher {
        Hasher::new_with_initial_len(init, 0)
    }

    /// As [`Hasher::new_with_initial`], with the count of those earlier bytes.
    pub fn new_with_initial_len(init: u32, amount: u64) -> Hasher {
        Hasher {
            state: !init,
            amount,
        }
    }

    /// Adds `bytes` to the checksum.
    pub fn update(&mut self, bytes: &[u8]) {
        self.state = advance(self.state, bytes);
        self.amount += bytes.len() as u64;
    }

    /// The CRC of every byte given so far.
    pub fn finalize(self) -> u32 {
        !self.state
    }

    /// Back to the state of [`Hasher::new`].
    pub fn reset(&mut self) {
        *self = Hasher::new();
    }

    /// Appends the bytes `other` has seen, as if they had been given to
    /// this hasher after its own.
    pub fn combine(&mut self, other: &Hasher) {
        let joined = shift_over_zeros(!self.state, other.amount) ^ !other.state;
        self.state = !joined;
        self.amount += other.amount;
    }

    /// How many bytes have been given.
    pub fn amount(&self) -> u64 {
        self.amount
    }
}

/// The CRC-32 of `buf`.
pub fn hash(buf: &[u8]) -> u32 {
    let mut h = Hasher::new();
    h.update(buf);
    h.finalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// Bit-by-bit CRC, the definition the tables must agree with.
    fn reference(data: &[u8]) -> u32 {
        let mut c = 0xFFFF_FFFFu32;
        for &b in data {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 { POLY ^ (c >> 1) } else { c >> 1 };
            }
        }
        !c
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn check_values_of_the_standard() {
        // The CRC catalogue's check value of CRC-32/ISO-HDLC, and PNG's IEND chunk.
        assert_eq!(hash(b"123456789"), 0xCBF4_3926);
        assert_eq!(hash(b"IEND"), 0xAE42_6082);
        assert_eq!(hash(b""), 0);
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn any_split_and_length_matches_the_bitwise_definition() {
        let data: Vec<u8> = (0..1000u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        for len in [0, 1, 7, 8, 9, 15, 16, 17, 100, 1000] {
            let want = reference(&data[..len]);
            assert_eq!(hash(&data[..len]), want, "length {len}");
            for split in [0, 1, 3, 8, len / 2, len] {
                let split = split.min(len);
                let mut h = Hasher::new();
                h.update(&data[..split]);
                let mut h = Hasher::new_with_initial_len(h.clone().finalize(), h.amount());
                h.update(&data[split..len]);
                assert_eq!(h.amount(), len as u64);
                assert_eq!(h.finalize(), want, "length {len} split {split}");
            }
        }
        // combine: the CRC of a concatenation from the CRCs of its parts.
        for (a, b) in [(0, 0), (0, 5), (3, 0), (1, 1), (13, 1000 - 13), (500, 500)] {
            let mut left = Hasher::new();
            left.update(&data[..a]);
            let mut right = Hasher::new();
            right.update(&data[a..a + b]);
            left.combine(&right);
            assert_eq!(left.amount(), (a + b) as u64);
            assert_eq!(
                left.finalize(),
                reference(&data[..a + b]),
                "combine {a} + {b}"
            );
        }
        let mut h = Hasher::new();
        h.update(b"junk");
        h.reset();
        h.update(b"123456789");
        assert_eq!(h.finalize(), 0xCBF4_3926);
    }
}
