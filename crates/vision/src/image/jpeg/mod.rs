//! JPEG decoding (ITU T.81): baseline and extended sequential and
//! progressive Huffman-coded 8-bit images, any sampling factors, restart
//! intervals; grey, YCbCr, RGB, CMYK and YCCK (Adobe) colour.
//!
//! Sequential scans are transformed block by block into one plane per
//! component; progressive scans keep the coefficients until the last scan.
//! Chroma is upsampled by replication. Arithmetic coding, 12-bit samples,
//! lossless and hierarchical JPEG are refused with their name.

mod blocks;
mod huffman;
mod idct;
mod output;
#[cfg(test)]
mod tests;

use blocks::{progressive_block, sequential_block, Tables};
use huffman::{BitReader, Huffman};

/// Zig-zag position `k` -> natural (row-major) index in the 8x8 block.
const ZIGZAG: [u8; 64] = [
    0, 1, 8, 16, 9, 2, 3, 10, 17, 24, 32, 25, 18, 11, 4, 5, 12, 19, 26, 33, 40, 48, 41, 34, 27, 20,
    13, 6, 7, 14, 21, 28, 35, 42, 49, 56, 57, 50, 43, 36, 29, 22, 15, 23, 30, 37, 44, 51, 58, 59,
    52, 45, 38, 31, 39, 46, 53, 60, 61, 54, 47, 55, 62, 63,
];

/// Why a JPEG could not be decoded.
#[derive(Debug, PartialEq)]
pub enum JpegError {
    /// Damaged or truncated data (the detail says where).
    Corrupt(String),
    /// A valid JPEG of a kind this decoder does not read.
    Unsupported(String),
    /// The decode would need more memory than allowed.
    TooLarge,
}

fn corrupt(detail: impl Into<String>) -> JpegError {
    JpegError::Corrupt(detail.into())
}

/// A decoded image: 1 channel (grey) or 3 (RGB), rows packed.
pub struct JpegImage {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// 1 (grey) or 3 (RGB).
    pub channels: u8,
    /// `width * height * channels` samples, rows packed.
    pub pixels: Vec<u8>,
}

/// The frame header (SOF) as needed for checks before decoding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JpegHeader {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Output channels: 1 for grey, 3 otherwise.
    pub channels: u8,
}

struct Component {
    id: u8,
    h: usize,
    v: usize,
    quant: usize,
    dc_table: usize,
    ac_table: usize,
    /// Blocks a non-interleaved scan covers (the component's own size).
    blocks_w: usize,
    blocks_h: usize,
    /// Blocks of the MCU-padded plane.
    padded_w: usize,
    padded_h: usize,
    plane: Vec<u8>,
    /// Progressive only: quantised coefficients, 64 per block, zig-zag order.
    coefs: Vec<i16>,
    dc_pred: i32,
}

struct Frame {
    width: usize,
    height: usize,
    progressive: bool,
    components: Vec<Component>,
    h_max: usize,
    v_max: usize,
    mcus_x: usize,
    mcus_y: usize,
}

struct Scan {
    /// Indices into the frame's components.
    components: Vec<usize>,
    ss: usize,
    se: usize,
    ah: u32,
    al: u32,
}

struct Decoder {
    quant: [[u16; 64]; 4],
    quant_defined: [bool; 4],
    dc: [Option<Huffman>; 4],
    ac: [Option<Huffman>; 4],
    restart_interval: usize,
    adobe_transform: Option<u8>,
    frame: Option<Frame>,
    eob_run: u32,
    max_alloc: u64,
}

/// Read the frame header only (size and output channels).
pub fn read_header(bytes: &[u8]) -> Result<JpegHeader, JpegError> {
    let mut d = Decoder::new(u64::MAX);
    d.run(bytes, true)?;
    let f = d.frame.as_ref().ok_or_else(|| corrupt("no frame header"))?;
    Ok(JpegHeader {
        width: f.width as u32,
        height: f.height as u32,
        channels: if f.components.len() == 1 { 1 } else { 3 },
    })
}

/// Decode a whole JPEG; `max_alloc` bounds the working memory (planes and
/// coefficients) besides the output.
pub fn decode(bytes: &[u8], max_alloc: u64) -> Result<JpegImage, JpegError> {
    let mut d = Decoder::new(max_alloc);
    d.run(bytes, false)?;
    d.finish()
}

fn u16_at(b: &[u8], i: usize) -> Result<usize, JpegError> {
    match b.get(i..i + 2) {
        Some(s) => Ok(u16::from_be_bytes([s[0], s[1]]) as usize),
        None => Err(corrupt("the file ends inside a marker segment")),
    }
}

impl Decoder {
    fn new(max_alloc: u64) -> Decoder {
        Decoder {
            quant: [[0; 64]; 4],
            quant_defined: [false; 4],
            dc: [None, None, None, None],
            ac: [None, None, None, None],
            restart_interval: 0,
            adobe_transform: None,
            frame: None,
            eob_run: 0,
            max_alloc,
        }
    }

    /// Walk the markers; with `header_only`, stop at the frame header.
    fn run(&mut self, b: &[u8], header_only: bool) -> Result<(), JpegError> {
        if b.get(..2) != Some(&[0xFF, 0xD8]) {
            return Err(corrupt("no start-of-image marker"));
        }
        let mut pos = 2;
        let mut scans = 0;
        loop {
            // Find the next marker (fill bytes 0xFF may precede it).
            while pos < b.len() && b[pos] != 0xFF {
                pos += 1;
            }
            while pos < b.len() && b[pos] == 0xFF {
                pos += 1;
            }
            let Some(&marker) = b.get(pos) else {
                // Truncated: what was decoded is kept.
                return if scans > 0 {
                    Ok(())
                } else {
                    Err(corrupt("the file ends before any image data"))
                };
            };
            pos += 1;
            match marker {
                0xD8 | 0x01 | 0xD0..=0xD7 => continue,
                0xD9 => {
                    return if scans > 0 || header_only {
                        Ok(())
                    } else {
                        Err(corrupt("no image data before the end-of-image marker"))
                    };
                }
                _ => {}
            }
            let len = u16_at(b, pos)?;
            if len < 2 {
                return Err(corrupt("bad marker segment length"));
            }
            let body = b
                .get(pos + 2..pos + len)
                .ok_or_else(|| corrupt("the file ends inside a marker segment"))?;
            match marker {
                0xC0..=0xC2 => {
                    if self.frame.is_some() {
                        return Err(JpegError::Unsupported("more than one frame".into()));
                    }
                    self.read_frame(body, marker == 0xC2)?;
                    if header_only {
                        return Ok(());
                    }
                }
                0xC3 | 0xC5..=0xC7 | 0xCB | 0xCD..=0xCF => {
                    return Err(JpegError::Unsupported(
                        "lossless or hierarchical JPEG".into(),
                    ));
                }
                0xC9 | 0xCA => return Err(JpegError::Unsupported("arithmetic-coded JPEG".into())),
                0xC4 => self.read_huffman(body)?,
                0xDB => self.read_quant(body)?,
                0xDD => self.restart_interval = u16_at(body, 0)?,
                0xEE if body.starts_with(b"Adobe") && body.len() >= 12 => {
                    self.adobe_transform = Some(body[11]);
                }
                0xDA => {
                    if header_only {
                        return Err(corrupt("scan data before the frame header"));
                    }
                    let scan = self.read_scan(body)?;
                    pos = self.decode_scan(b, pos + len, &scan)?;
                    scans += 1;
                    continue;
                }
                _ => {} // APPn, COM, DNL, ...: skipped
            }
            pos += len;
        }
    }

    fn read_frame(&mut self, s: &[u8], progressive: bool) -> Result<(), JpegError> {
        if s.len() < 6 {
            return Err(corrupt("short frame header"));
        }
        if s[0] != 8 {
            return Err(JpegError::Unsupported(format!("{}-bit samples", s[0])));
        }
        let height = u16_at(s, 1)?;
        let width = u16_at(s, 3)?;
        let n = s[5] as usize;
        if height == 0 {
            return Err(JpegError::Unsupported(
                "height defined by a DNL marker".into(),
            ));
        }
        if width == 0 {
            return Err(corrupt("zero width"));
        }
        if !matches!(n, 1 | 3 | 4) {
            return Err(JpegError::Unsupported(format!("{n} colour components")));
        }
        if s.len() < 6 + 3 * n {
            return Err(corrupt("short frame header"));
        }
        let mut components = Vec::with_capacity(n);
        for c in s[6..6 + 3 * n].chunks_exact(3) {
            let (h, v) = ((c[1] >> 4) as usize, (c[1] & 15) as usize);
            if !(1..=4).contains(&h) || !(1..=4).contains(&v) || c[2] > 3 {
                return Err(corrupt(
                    "bad sampling factor or quantisation table in the frame header",
                ));
            }
            components.push(Component {
                id: c[0],
                h,
                v,
                quant: c[2] as usize,
                dc_table: 0,
                ac_table: 0,
                blocks_w: 0,
                blocks_h: 0,
                padded_w: 0,
                padded_h: 0,
                plane: Vec::new(),
                coefs: Vec::new(),
                dc_pred: 0,
            });
        }
        if n == 1 {
            // A single component is never interleaved: its MCU is one block.
            components[0].h = 1;
            components[0].v = 1;
        }
        let h_max = components.iter().map(|c| c.h).max().unwrap_or(1);
        let v_max = components.iter().map(|c| c.v).max().unwrap_or(1);
        let mcus_x = width.div_ceil(8 * h_max);
        let mcus_y = height.div_ceil(8 * v_max);
        for c in &mut components {
            c.blocks_w = (width * c.h).div_ceil(h_max).div_ceil(8);
            c.blocks_h = (height * c.v).div_ceil(v_max).div_ceil(8);
            c.padded_w = mcus_x * c.h;
            c.padded_h = mcus_y * c.v;
        }
        self.frame = Some(Frame {
            width,
            height,
            progressive,
            components,
            h_max,
            v_max,
            mcus_x,
            mcus_y,
        });
        Ok(())
    }

    fn read_huffman(&mut self, mut s: &[u8]) -> Result<(), JpegError> {
        while !s.is_empty() {
            if s.len() < 17 {
                return Err(corrupt("short Huffman table"));
            }
            let (class, id) = (s[0] >> 4, (s[0] & 15) as usize);
            if class > 1 || id > 3 {
                return Err(corrupt("bad Huffman table class or number"));
            }
            let counts: [u8; 16] = std::array::from_fn(|i| s[1 + i]);
            let total: usize = counts.iter().map(|&c| c as usize).sum();
            let symbols = s
                .get(17..17 + total)
                .ok_or_else(|| corrupt("short Huffman table"))?;
            let table = Huffman::new(&counts, symbols).map_err(corrupt)?;
            if class == 0 {
                self.dc[id] = Some(table);
            } else {
                self.ac[id] = Some(table);
            }
            s = &s[17 + total..];
        }
        Ok(())
    }

    fn read_quant(&mut self, mut s: &[u8]) -> Result<(), JpegError> {
        while !s.is_empty() {
            let (precision, id) = (s[0] >> 4, (s[0] & 15) as usize);
            if id > 3 || precision > 1 {
                return Err(corrupt("bad quantisation table number or precision"));
            }
            let size = if precision == 0 { 64 } else { 128 };
            let values = s
                .get(1..1 + size)
                .ok_or_else(|| corrupt("short quantisation table"))?;
            for k in 0..64 {
                self.quant[id][k] = if precision == 0 {
                    values[k] as u16
                } else {
                    u16::from_be_bytes([values[2 * k], values[2 * k + 1]])
                };
            }
            self.quant_defined[id] = true;
            s = &s[1 + size..];
        }
        Ok(())
    }

    fn read_scan(&mut self, s: &[u8]) -> Result<Scan, JpegError> {
        let frame = self
            .frame
            .as_mut()
            .ok_or_else(|| corrupt("scan data before the frame header"))?;
        let n = *s.first().ok_or_else(|| corrupt("short scan header"))? as usize;
        if n == 0 || n > 4 || s.len() < 4 + 2 * n {
            return Err(corrupt("bad scan header"));
        }
        let mut components = Vec::with_capacity(n);
        for c in s[1..1 + 2 * n].chunks_exact(2) {
            let index = frame
                .components
                .iter()
                .position(|f| f.id == c[0])
                .ok_or_else(|| corrupt(format!("scan of component {}, not in the frame", c[0])))?;
            let comp = &mut frame.components[index];
            comp.dc_table = (c[1] >> 4) as usize & 3;
            comp.ac_table = (c[1] & 15) as usize & 3;
            components.push(index);
        }
        let tail = &s[1 + 2 * n..];
        let scan = Scan {
            components,
            ss: tail[0] as usize,
            se: tail[1] as usize,
            ah: (tail[2] >> 4) as u32,
            al: (tail[2] & 15) as u32,
        };
        if frame.progressive {
            let bad = scan.ss > scan.se
                || scan.se > 63
                || (scan.ss == 0 && scan.se != 0)
                || (scan.ss > 0 && scan.components.len() != 1)
                || scan.al > 13;
            if bad {
                return Err(corrupt("bad progressive scan parameters"));
            }
        }
        Ok(scan)
    }

    /// Allocate the planes (and coefficients) at the first scan.
    fn allocate(&mut self) -> Result<(), JpegError> {
        let frame = self
            .frame
            .as_mut()
            .ok_or_else(|| corrupt("scan data before the frame header"))?;
        if !frame.components[0].plane.is_empty() {
            return Ok(());
        }
        let mut bytes: u64 = 0;
        for c in &frame.components {
            let pixels = (c.padded_w * c.padded_h * 64) as u64;
            bytes += pixels * if frame.progressive { 3 } else { 1 };
        }
        if bytes > self.max_alloc {
            return Err(JpegError::TooLarge);
        }
        for c in &mut frame.components {
            let pixels = c.padded_w * c.padded_h * 64;
            c.plane = vec![128; pixels];
            if frame.progressive {
                c.coefs = vec![0; pixels];
            }
        }
        Ok(())
    }

    /// Decode one scan's entropy-coded data starting at `pos`; returns the
    /// position after it.
    fn decode_scan(&mut self, b: &[u8], pos: usize, scan: &Scan) -> Result<usize, JpegError> {
        self.allocate()?;
        let frame = self
            .frame
            .as_mut()
            .ok_or_else(|| corrupt("scan data before the frame header"))?;
        for &i in &scan.components {
            let c = &mut frame.components[i];
            c.dc_pred = 0;
            let needs_dc = scan.ss == 0 && scan.ah == 0;
            let needs_ac = !frame.progressive || scan.ss > 0;
            if needs_dc && self.dc[c.dc_table].is_none()
                || needs_ac && self.ac[c.ac_table].is_none()
            {
                return Err(corrupt("a scan uses a Huffman table that is not defined"));
            }
            if !frame.progressive && !self.quant_defined[c.quant] {
                return Err(corrupt(
                    "a component uses a quantisation table that is not defined",
                ));
            }
        }
        self.eob_run = 0;
        let mut bits = BitReader::new(b, pos);
        let single = scan.components.len() == 1;
        let (units_x, units_y) = if single {
            let c = &frame.components[scan.components[0]];
            (c.blocks_w, c.blocks_h)
        } else {
            (frame.mcus_x, frame.mcus_y)
        };
        let tables = Tables {
            dc: &self.dc,
            ac: &self.ac,
            quant: &self.quant,
        };
        let mut done = 0usize;
        for uy in 0..units_y {
            for ux in 0..units_x {
                if self.restart_interval > 0 && done > 0 && done % self.restart_interval == 0 {
                    bits.restart();
                    self.eob_run = 0;
                    for &i in &scan.components {
                        frame.components[i].dc_pred = 0;
                    }
                }
                for &i in &scan.components {
                    let c = &mut frame.components[i];
                    let (bw, bh) = if single { (1, 1) } else { (c.h, c.v) };
                    for by in 0..bh {
                        for bx in 0..bw {
                            let (x, y) = (ux * bw + bx, uy * bh + by);
                            if frame.progressive {
                                progressive_block(
                                    &mut bits,
                                    &tables,
                                    c,
                                    x,
                                    y,
                                    scan,
                                    &mut self.eob_run,
                                )?;
                            } else {
                                sequential_block(&mut bits, &tables, c, x, y)?;
                            }
                        }
                    }
                }
                done += 1;
            }
        }
        Ok(bits.pos)
    }

    fn finish(self) -> Result<JpegImage, JpegError> {
        let mut frame = self.frame.ok_or_else(|| corrupt("no frame header"))?;
        if frame.progressive {
            for c in &mut frame.components {
                let q = &self.quant[c.quant];
                let stride = c.padded_w * 8;
                let mut block = [0i32; 64];
                for (n, coefs) in c.coefs.chunks_exact(64).enumerate() {
                    for k in 0..64 {
                        block[ZIGZAG[k] as usize] = (coefs[k] as i32).wrapping_mul(q[k] as i32);
                    }
                    let (x, y) = (n % c.padded_w, n / c.padded_w);
                    idct::idct_block(&block, &mut c.plane[y * 8 * stride + x * 8..], stride);
                }
            }
        }
        Ok(output::output(&frame, self.adobe_transform))
    }
}
