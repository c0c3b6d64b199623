//! The coefficient blocks of a scan: sequential (decoded, dequantised and
//! transformed at once) and progressive (DC or one AC band, first pass or
//! refinement, kept until the last scan).

use super::huffman::{BitReader, Huffman};
use super::{corrupt, idct, Component, JpegError, Scan, ZIGZAG};

pub(super) struct Tables<'a> {
    pub(super) dc: &'a [Option<Huffman>; 4],
    pub(super) ac: &'a [Option<Huffman>; 4],
    pub(super) quant: &'a [[u16; 64]; 4],
}

fn table(t: &Option<Huffman>) -> Result<&Huffman, JpegError> {
    t.as_ref()
        .ok_or_else(|| corrupt("a scan uses a Huffman table that is not defined"))
}

/// One block of a sequential scan: decoded, dequantised, transformed into
/// the plane.
pub(super) fn sequential_block(
    bits: &mut BitReader,
    t: &Tables,
    c: &mut Component,
    x: usize,
    y: usize,
) -> Result<(), JpegError> {
    let (dc, ac) = (table(&t.dc[c.dc_table])?, table(&t.ac[c.ac_table])?);
    let q = &t.quant[c.quant];
    let mut block = [0i32; 64];
    let s = bits.decode(dc).map_err(corrupt)? as u32;
    if s > 16 {
        return Err(corrupt("bad DC coefficient size"));
    }
    c.dc_pred = c.dc_pred.wrapping_add(bits.extend(s));
    block[0] = c.dc_pred.wrapping_mul(q[0] as i32);
    let mut k = 1;
    while k < 64 {
        let rs = bits.decode(ac).map_err(corrupt)?;
        let (r, s) = ((rs >> 4) as usize, (rs & 15) as u32);
        if s == 0 {
            if r != 15 {
                break;
            }
            k += 16;
            continue;
        }
        k += r;
        if k > 63 {
            break; // damaged data: the rest of the block stays zero
        }
        block[ZIGZAG[k] as usize] = bits.extend(s).wrapping_mul(q[k] as i32);
        k += 1;
    }
    let stride = c.padded_w * 8;
    idct::idct_block(&block, &mut c.plane[y * 8 * stride + x * 8..], stride);
    Ok(())
}

/// One block of a progressive scan (T.81 G.1.2): DC or one AC band, first
/// pass or refinement, into the stored coefficients.
pub(super) fn progressive_block(
    bits: &mut BitReader,
    t: &Tables,
    c: &mut Component,
    x: usize,
    y: usize,
    scan: &Scan,
    eob_run: &mut u32,
) -> Result<(), JpegError> {
    let at = (y * c.padded_w + x) * 64;
    let coefs = &mut c.coefs[at..at + 64];
    let al = scan.al;
    if scan.ss == 0 {
        if scan.ah == 0 {
            let s = bits.decode(table(&t.dc[c.dc_table])?).map_err(corrupt)? as u32;
            if s > 16 {
                return Err(corrupt("bad DC coefficient size"));
            }
            c.dc_pred = c.dc_pred.wrapping_add(bits.extend(s));
            coefs[0] = (c.dc_pred << al) as i16;
        } else if bits.bit() {
            coefs[0] |= 1 << al;
        }
        return Ok(());
    }
    let ac = table(&t.ac[c.ac_table])?;
    let (ss, se) = (scan.ss, scan.se);
    if scan.ah == 0 {
        if *eob_run > 0 {
            *eob_run -= 1;
            return Ok(());
        }
        let mut k = ss;
        while k <= se {
            let rs = bits.decode(ac).map_err(corrupt)?;
            let (r, s) = ((rs >> 4) as u32, (rs & 15) as u32);
            if s == 0 {
                if r < 15 {
                    *eob_run = (1 << r) - 1;
                    if r > 0 {
                        *eob_run += bits.bits(r) as u32;
                    }
                    break;
                }
                k += 16;
                continue;
            }
            k += r as usize;
            if k > 63 {
                break;
            }
            coefs[k] = (bits.extend(s) << al) as i16;
            k += 1;
        }
        return Ok(());
    }
    // Refinement: one more bit of every non-zero coefficient in the band,
    // and newly non-zero coefficients of magnitude 1 << al.
    let p1: i16 = 1 << al;
    let m1: i16 = -1 << al;
    let refine = |bits: &mut BitReader, v: &mut i16| {
        if bits.bit() && *v & p1 == 0 {
            *v = v.wrapping_add(if *v >= 0 { p1 } else { m1 });
        }
    };
    let mut k = ss;
    if *eob_run == 0 {
        while k <= se {
            let rs = bits.decode(ac).map_err(corrupt)?;
            let (mut r, s) = ((rs >> 4) as i32, rs & 15);
            let mut value = 0;
            if s != 0 {
                value = if bits.bit() { p1 } else { m1 };
            } else if r != 15 {
                *eob_run = 1 << r;
                if r > 0 {
                    *eob_run += bits.bits(r as u32) as u32;
                }
                break;
            }
            while k <= se {
                if coefs[k] != 0 {
                    refine(bits, &mut coefs[k]);
                } else {
                    if r == 0 {
                        break;
                    }
                    r -= 1;
                }
                k += 1;
            }
            if value != 0 && k <= se {
                coefs[k] = value;
            }
            k += 1;
        }
    }
    if *eob_run > 0 {
        while k <= se {
            if coefs[k] != 0 {
                refine(bits, &mut coefs[k]);
            }
            k += 1;
        }
        *eob_run -= 1;
    }
    Ok(())
}
