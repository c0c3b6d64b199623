//! Decimal text to `f64` without the standard library's tables.
//!
//! `str::parse::<f64>` is exact but brings a 10 KB table of 128-bit powers
//! of five into the wasm (incompressible: 10 KB of the gzip budget). Here the
//! common case (up to 15-16 significant digits and a decimal exponent within
//! ±22) is Clinger's exact fast path, one correctly rounded division or
//! product of two exact doubles; everything else is computed in double-double
//! arithmetic (about 104 bits), whose single final rounding gives the
//! correctly rounded double except within 2^-100 of a halfway point.
//! The grammar is the standard library's: an optional sign, digits with an
//! optional point (`1.`, `.5`), an optional exponent (`e-3`, `E+7`), or
//! `inf`, `infinity`, `nan` in any case. No surrounding whitespace.

/// Parse `text` as an `f64` (see the module docs); `None` when it is not a
/// number.
pub fn parse_f64(text: &str) -> Option<f64> {
    let b = text.as_bytes();
    let (negative, rest) = match b.first() {
        Some(b'-') => (true, &b[1..]),
        Some(b'+') => (false, &b[1..]),
        _ => (false, b),
    };
    let signed = |v: f64| if negative { -v } else { v };
    if let Some(special) = special_value(rest) {
        return Some(signed(special));
    }
    let (mantissa, exponent) = decimal(rest)?;
    Some(signed(to_f64(mantissa, exponent)))
}

fn special_value(b: &[u8]) -> Option<f64> {
    let is = |word: &str| b.eq_ignore_ascii_case(word.as_bytes());
    if is("inf") || is("infinity") {
        Some(f64::INFINITY)
    } else if is("nan") {
        Some(f64::NAN)
    } else {
        None
    }
}

/// Significant digits (the first 19, the rest only as a sticky bit) and the
/// power of ten they are scaled by. `None` when `b` is not `digits[.digits]
/// [e[sign]digits]` with at least one digit in the number.
fn decimal(b: &[u8]) -> Option<(Digits, i64)> {
    let mut digits = Digits {
        value: 0,
        count: 0,
        sticky: false,
    };
    let mut exponent: i64 = 0;
    let mut seen_digit = false;
    let mut i = 0;
    let mut after_point = false;
    while i < b.len() {
        match b[i] {
            c @ b'0'..=b'9' => {
                seen_digit = true;
                let d = u64::from(c - b'0');
                if digits.count < 19 {
                    if digits.count > 0 || d != 0 {
                        digits.value = digits.value * 10 + d;
                        digits.count += 1;
                    }
                    if after_point {
                        exponent -= 1;
                    }
                } else {
                    digits.sticky |= d != 0;
                    if !after_point {
                        exponent += 1;
                    }
                }
            }
            b'.' if !after_point => after_point = true,
            b'e' | b'E' => break,
            _ => return None,
        }
        i += 1;
    }
    if !seen_digit {
        return None;
    }
    if i < b.len() {
        let e = &b[i + 1..];
        let (sign, e) = match e.first() {
            Some(b'-') => (-1, &e[1..]),
            Some(b'+') => (1, &e[1..]),
            _ => (1, e),
        };
        if e.is_empty() || !e.iter().all(u8::is_ascii_digit) {
            return None;
        }
        // Saturate: anything beyond ±10^6 is zero or infinity anyway.
        let value = e.iter().fold(0i64, |acc, &c| {
            (acc * 10 + i64::from(c - b'0')).min(1_000_000)
        });
        exponent += sign * value;
    }
    Some((digits, exponent))
}

struct Digits {
    value: u64,
    count: u32,
    sticky: bool,
}

/// Exact powers of ten as doubles (10^22 is the last one that is exact).
const EXACT_POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

fn to_f64(digits: Digits, exponent: i64) -> f64 {
    let w = digits.value;
    if w == 0 {
        return 0.0;
    }
    // Magnitude bounds: w < 10^19, so below 10^-344 it rounds to zero and at
    // or above 10^310 to infinity.
    let magnitude = exponent + i64::from(digits.count);
    if magnitude < -343 {
        return 0.0;
    }
    if magnitude > 310 {
        return f64::INFINITY;
    }
    if !digits.sticky && w <= 1 << 53 && exponent.abs() <= 22 {
        let p = EXACT_POW10[exponent.unsigned_abs() as usize];
        return if exponent < 0 {
            w as f64 / p
        } else {
            w as f64 * p
        };
    }
    // w (+ half a unit of its last digit when digits were dropped) as a
    // double-double, exactly; pre-scaled by a power of two (exact) so that
    // no intermediate overflows or leaves the normal range.
    let scale: i32 = if magnitude > 300 {
        -128
    } else if magnitude < -290 {
        128
    } else {
        0
    };
    let hi = w as f64;
    let lo = (i128::from(w) - hi as i128) as f64;
    let mut x = Dd {
        hi: hi * 2f64.powi(scale),
        lo: lo * 2f64.powi(scale),
    };
    if digits.sticky {
        x = x.add(Dd {
            hi: 0.5 * 2f64.powi(scale),
            lo: 0.0,
        });
    }
    let mut e = exponent;
    while e != 0 {
        let step = e.clamp(-300, 300);
        let p = pow10(step.unsigned_abs() as u32);
        x = if step < 0 { x.div(p) } else { x.mul(p) };
        e -= step;
    }
    let rounded = x.hi + x.lo;
    if scale <= 0 {
        // Exact rescaling (or the correct overflow to infinity).
        return rounded * 2f64.powi(-scale);
    }
    let unscaled = rounded * 2f64.powi(-scale);
    if unscaled >= f64::MIN_POSITIVE {
        return unscaled;
    }
    // A subnormal result: round hi on the subnormal grid, then let lo move
    // it by one step when hi's rounding error plus lo exceeds half a step.
    let h = x.hi * 2f64.powi(-scale);
    let error = x.hi - h * 2f64.powi(scale); // exact: below one step
    let half_step = 2f64.powi(-1075 + scale);
    let odd = h.to_bits() & 1 == 1;
    let above = (error - half_step) + x.lo; // > 0: past the upper midpoint
    let below = (error + half_step) + x.lo; // < 0: past the lower midpoint
    if above > 0.0 || (above == 0.0 && odd) {
        f64::from_bits(h.to_bits() + 1)
    } else if h > 0.0 && (below < 0.0 || (below == 0.0 && odd)) {
        f64::from_bits(h.to_bits() - 1)
    } else {
        h
    }
}

/// 10^n (n <= 300) as a double-double, by squaring.
fn pow10(mut n: u32) -> Dd {
    let mut result = Dd { hi: 1.0, lo: 0.0 };
    let mut base = Dd { hi: 10.0, lo: 0.0 };
    while n > 0 {
        if n & 1 == 1 {
            result = result.mul(base);
        }
        n >>= 1;
        if n > 0 {
            base = base.mul(base);
        }
    }
    result
}

/// An unevaluated sum `hi + lo` with |lo| <= ulp(hi) / 2.
#[derive(Clone, Copy)]
struct Dd {
    hi: f64,
    lo: f64,
}

/// a + b = s + e exactly (Knuth's two-sum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// a * b = p + e exactly (Dekker's product with Veltkamp's split; no FMA,
/// which wasm lacks).
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let (ah, al) = split(a);
    let (bh, bl) = split(b);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

fn split(a: f64) -> (f64, f64) {
    // Scaled down first so that the 2^27 + 1 product cannot overflow.
    if a.abs() > 1e300 {
        let (h, l) = split(a * 2f64.powi(-28));
        return (h * 2f64.powi(28), l * 2f64.powi(28));
    }
    let t = 134_217_729.0 * a;
    let hi = t - (t - a);
    (hi, a - hi)
}

impl Dd {
    fn normalized(hi: f64, lo: f64) -> Dd {
        let (hi, lo) = two_sum(hi, lo);
        Dd { hi, lo }
    }

    fn add(self, o: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, o.hi);
        Dd::normalized(s, e + self.lo + o.lo)
    }

    fn mul(self, o: Dd) -> Dd {
        let (p, e) = two_prod(self.hi, o.hi);
        Dd::normalized(p, e + (self.hi * o.lo + self.lo * o.hi))
    }

    fn div(self, o: Dd) -> Dd {
        // One Newton-style correction of the double quotient.
        let q1 = self.hi / o.hi;
        let r = self.add(o.mul(Dd { hi: -q1, lo: 0.0 }));
        let q2 = r.hi / o.hi;
        let r = r.add(o.mul(Dd { hi: -q2, lo: 0.0 }));
        let q3 = r.hi / o.hi;
        Dd::normalized(q1, q2).add(Dd { hi: q3, lo: 0.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::parse_f64;

    fn same(text: &str) {
        let ours = parse_f64(text);
        let std = text.parse::<f64>().ok();
        match (ours, std) {
            (Some(a), Some(b)) if a.is_nan() && b.is_nan() => {}
            (Some(a), Some(b)) => {
                assert_eq!(a.to_bits(), b.to_bits(), "{text}: ours {a:e}, std {b:e}")
            }
            (a, b) => assert_eq!(a, b, "{text}"),
        }
    }

    #[test]
    fn grammar_matches_the_standard_library() {
        for text in [
            "0",
            "-0",
            "+0",
            "1",
            "-1",
            "1.",
            ".5",
            "-.5",
            "+.5e1",
            "1e5",
            "1E5",
            "1e+5",
            "1e-5",
            "00012.5000",
            "inf",
            "-inf",
            "Infinity",
            "INF",
            "nan",
            "NaN",
            "-nan",
            "",
            "-",
            "+",
            ".",
            "e5",
            "1e",
            "1e+",
            "1.2.3",
            "1,5",
            " 1",
            "1 ",
            "0x10",
            "1_000",
            "infinit",
            "--1",
            "1e5.5",
            "١",
        ] {
            same(text);
        }
    }

    #[test]
    fn short_decimals_round_exactly() {
        for text in [
            "0.1",
            "0.2",
            "0.3",
            "22.5778e-3",
            "0.0225778",
            "123.456",
            "-987654.321",
            "9007199254740993",
            "1e22",
            "1e23",
            "3.14159265358979",
            "2.718281828459045",
            "0.12345678901234567",
            "1234567890123456789",
            "12345678901234567890123",
            "0.000000000000000000001234",
            "179769313486231570000000000000000000000e270",
        ] {
            same(text);
        }
    }

    #[test]
    fn extremes_match_the_standard_library() {
        for text in [
            "1.7976931348623157e308",
            "1.7976931348623158e308",
            "1.8e308",
            "1e309",
            "2.2250738585072014e-308",
            "4.9e-324",
            "5e-324",
            "2e-324",
            "2.5e-324",
            "2.4e-324",
            "2.4703282292062328e-324",
            "1e-400",
            "1e-343",
            "123e-330",
            "1e1000000000",
            "0.0000e99999",
            "1e-1000000000",
        ] {
            same(text);
        }
    }

    #[test]
    fn random_decimals_are_correctly_rounded() {
        // Doubles printed with 1 to 19 significant digits at exponents
        // across the whole range (subnormals and overflow included), compared
        // bit for bit with std.
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut mismatches = Vec::new();
        for _ in 0..200_000 {
            let digits = 1 + next() % 19;
            let mantissa = next() % 10u64.pow(digits as u32);
            let exponent = (next() % 670) as i64 - 350;
            let text = format!("{mantissa}e{exponent}");
            let ours = parse_f64(&text).map(f64::to_bits);
            if ours != text.parse::<f64>().ok().map(f64::to_bits) {
                mismatches.push(text);
            }
        }
        assert!(
            mismatches.is_empty(),
            "{} mismatches, e.g. {:?}",
            mismatches.len(),
            &mismatches[..mismatches.len().min(5)]
        );
        // And every double written shortest (17 digits at most) reads back.
        for _ in 0..100_000 {
            let v = f64::from_bits(next() >> 2);
            let text = format!("{v:e}");
            assert_eq!(
                parse_f64(&text).map(f64::to_bits),
                Some(v.to_bits()),
                "{text}"
            );
        }
    }
}
