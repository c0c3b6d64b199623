//! Command-line values with a unit or a shape, read once for every command:
//! comma-separated lengths with one unit at the end (`--tcp 0,0,150mm`,
//! `--distance 0.4,0.6m`) and `AxB` pairs (`--grid 60x40`, `--size
//! 640x480`). Each command keeps its own message for a bad value.

use super::CliError;
use std::str::FromStr;

/// What a flag of lengths takes: how many numbers, and the words of its
/// messages.
pub struct LengthsFlag<'a> {
    /// The command, for the usage error (`plan`, `handeye`).
    pub command: &'a str,
    /// The flag as typed (`--tcp`).
    pub flag: &'a str,
    /// How many numbers.
    pub count: usize,
    /// What the message says is expected (`three numbers X,Y,Z`).
    pub expected: &'a str,
    /// Said after the missing unit's message (` (e.g. 0,0,150mm)`), or empty.
    pub unit_example: &'a str,
}

/// `text` as `flag.count` comma-separated numbers with one unit (mm, cm or
/// m) at the end, in metres.
pub fn lengths_m(flag: &LengthsFlag, text: &str) -> Result<Vec<f64>, CliError> {
    let bad = |why: &str| CliError::usage(flag.command, format!("{} '{text}': {why}", flag.flag));
    let t = text.trim();
    let (body, scale) = if let Some(b) = t.strip_suffix("mm") {
        (b, 1e-3)
    } else if let Some(b) = t.strip_suffix("cm") {
        (b, 1e-2)
    } else if let Some(b) = t.strip_suffix('m') {
        (b, 1.0)
    } else {
        return Err(bad(&format!(
            "needs a unit: mm, cm or m{}",
            flag.unit_example
        )));
    };
    let v: Vec<f64> = body
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(flag.expected))?;
    if v.len() != flag.count || v.iter().any(|a| !a.is_finite()) {
        return Err(bad(flag.expected));
    }
    Ok(v.iter().map(|a| a * scale).collect())
}

/// `AxB` (or `AXB`) as `[A, B]`; `None` when either side is not a `T`.
pub fn by_pair<T: FromStr>(text: &str, trim: bool) -> Option<[T; 2]> {
    let (a, b) = text.split_once(['x', 'X'])?;
    let side = |s: &str| if trim { s.trim() } else { s }.parse::<T>().ok();
    Some([side(a)?, side(b)?])
}

#[cfg(test)]
mod tests {
    use super::*;

    const TCP: LengthsFlag = LengthsFlag {
        command: "handeye",
        flag: "--tcp",
        count: 3,
        expected: "expected three numbers X,Y,Z",
        unit_example: " (e.g. 0,0,150mm)",
    };

    #[test]
    fn lengths_take_one_unit_and_the_count_asked() {
        assert_eq!(lengths_m(&TCP, " 0, 0,150mm ").unwrap(), [0.0, 0.0, 0.15]);
        assert_eq!(lengths_m(&TCP, "1,2,3cm").unwrap(), [0.01, 0.02, 0.03]);
        assert_eq!(lengths_m(&TCP, "1,2,3m").unwrap(), [1.0, 2.0, 3.0]);
        assert_eq!(
            lengths_m(&TCP, "0,0,150").unwrap_err().to_string(),
            "handeye: --tcp '0,0,150': needs a unit: mm, cm or m (e.g. 0,0,150mm) \
             (see 'robocal handeye --help')"
        );
        for bad in ["1,2mm", "1,2,3,4mm", "1,x,3mm", "1,2,infmm"] {
            assert_eq!(
                lengths_m(&TCP, bad).unwrap_err().to_string(),
                format!(
                    "handeye: --tcp '{bad}': expected three numbers X,Y,Z \
                     (see 'robocal handeye --help')"
                )
            );
        }
    }

    #[test]
    fn pairs_split_at_x() {
        assert_eq!(by_pair::<usize>("60x40", false), Some([60, 40]));
        assert_eq!(by_pair::<usize>(" 12 X 8 ", true), Some([12, 8]));
        assert_eq!(by_pair::<usize>(" 12 X 8 ", false), None);
        assert_eq!(by_pair::<usize>("12", true), None);
        assert_eq!(by_pair::<usize>("12xa", true), None);
    }
}
