//! The entropy-coded data of a JPEG scan: a bit reader that undoes the
//! 0xFF00 byte stuffing and stops at markers, and canonical Huffman tables
//! with a 9-bit lookup (codes of up to 9 bits, nearly all in practice, in one
//! step; longer ones by the code-length limits of ITU T.81 F.2.2.3).

/// Bits of a lookup index: codes up to this long decode with one table read.
const FAST_BITS: u32 = 9;

/// A Huffman table (DHT) ready for decoding.
pub(super) struct Huffman {
    /// `(code length << 8) | symbol` for each 9-bit prefix; 0 when the code
    /// is longer than 9 bits.
    fast: [u16; 1 << FAST_BITS],
    /// Largest code of each length (index 1..=16), -1 when there is none.
    max_code: [i32; 17],
    /// `symbol index - code` for the codes of each length.
    offset: [i32; 17],
    symbols: Vec<u8>,
}

impl Huffman {
    /// Build from the 16 code counts and the symbols of a DHT segment.
    pub(super) fn new(counts: &[u8; 16], symbols: &[u8]) -> Result<Huffman, &'static str> {
        let total: usize = counts.iter().map(|&c| c as usize).sum();
        if total > 256 || total != symbols.len() {
            return Err("Huffman table with more than 256 codes");
        }
        let mut table = Huffman {
            fast: [0; 1 << FAST_BITS],
            max_code: [-1; 17],
            offset: [0; 17],
            symbols: symbols.to_vec(),
        };
        let mut code: u32 = 0;
        let mut index: usize = 0;
        for len in 1..=16u32 {
            let count = counts[len as usize - 1] as u32;
            table.offset[len as usize] = index as i32 - code as i32;
            for _ in 0..count {
                if len <= FAST_BITS {
                    let first = (code << (FAST_BITS - len)) as usize;
                    let entry = ((len as u16) << 8) | symbols[index] as u16;
                    table.fast[first..first + (1 << (FAST_BITS - len))].fill(entry);
                }
                code += 1;
                index += 1;
            }
            if count > 0 {
                table.max_code[len as usize] = code as i32 - 1;
            }
            if code > 1 << len {
                return Err("Huffman table with more codes than its code lengths allow");
            }
            code <<= 1;
        }
        Ok(table)
    }
}

/// A big-endian bit reader over entropy-coded bytes. Past a marker or the
/// end of the data it reads zero bits (a truncated file decodes to the end
/// with flat blocks, as libjpeg does, instead of failing).
pub(super) struct BitReader<'a> {
    data: &'a [u8],
    /// Next byte to load.
    pub(super) pos: usize,
    /// Loaded bits, left-aligned.
    acc: u64,
    /// Number of valid bits in `acc`.
    count: u32,
    /// A marker (or the end of the data) was reached: only zeros follow.
    at_marker: bool,
}

impl<'a> BitReader<'a> {
    pub(super) fn new(data: &'a [u8], pos: usize) -> BitReader<'a> {
        BitReader {
            data,
            pos,
            acc: 0,
            count: 0,
            at_marker: false,
        }
    }

    #[inline]
    fn refill(&mut self) {
        while self.count <= 56 {
            let mut byte = 0u8;
            if !self.at_marker {
                match self.data.get(self.pos) {
                    Some(0xFF) => {
                        if self.data.get(self.pos + 1) == Some(&0) {
                            byte = 0xFF;
                            self.pos += 2;
                        } else {
                            self.at_marker = true;
                        }
                    }
                    Some(&b) => {
                        byte = b;
                        self.pos += 1;
                    }
                    None => self.at_marker = true,
                }
            }
            self.acc |= (byte as u64) << (56 - self.count);
            self.count += 8;
        }
    }

    /// The next `n` bits (1..=16) as an unsigned number.
    #[inline]
    pub(super) fn bits(&mut self, n: u32) -> i32 {
        if self.count < n {
            self.refill();
        }
        let v = (self.acc >> (64 - n)) as i32;
        self.acc <<= n;
        self.count -= n;
        v
    }

    #[inline]
    pub(super) fn bit(&mut self) -> bool {
        self.bits(1) != 0
    }

    /// The next `n` bits (0..=16) as a signed coefficient (T.81 F.2.2.1
    /// EXTEND).
    #[inline]
    pub(super) fn extend(&mut self, n: u32) -> i32 {
        if n == 0 {
            return 0;
        }
        let v = self.bits(n);
        if v < 1 << (n - 1) {
            v - (1 << n) + 1
        } else {
            v
        }
    }

    /// The next Huffman-coded symbol.
    #[inline]
    pub(super) fn decode(&mut self, table: &Huffman) -> Result<u8, &'static str> {
        if self.count < 16 {
            self.refill();
        }
        let entry = table.fast[(self.acc >> (64 - FAST_BITS)) as usize];
        if entry != 0 {
            let len = (entry >> 8) as u32;
            self.acc <<= len;
            self.count -= len;
            return Ok(entry as u8);
        }
        let prefix = (self.acc >> 48) as i32;
        for len in FAST_BITS + 1..=16 {
            let code = prefix >> (16 - len);
            if code <= table.max_code[len as usize] {
                self.acc <<= len;
                self.count -= len;
                let index = (code + table.offset[len as usize]) as usize;
                return table
                    .symbols
                    .get(index)
                    .copied()
                    .ok_or("invalid Huffman code");
            }
        }
        Err("invalid Huffman code in the scan data")
    }

    /// At a restart interval's end: drop the bits left in the byte, step over
    /// the RSTn marker (or, in damaged data, up to the next marker).
    pub(super) fn restart(&mut self) {
        self.acc = 0;
        self.count = 0;
        self.at_marker = false;
        while self.pos + 1 < self.data.len() {
            if self.data[self.pos] == 0xFF {
                let m = self.data[self.pos + 1];
                if (0xD0..=0xD7).contains(&m) {
                    self.pos += 2;
                    return;
                }
                if m != 0 && m != 0xFF {
                    return; // another marker: the scan ended early
                }
            }
            self.pos += 1;
        }
    }
}
