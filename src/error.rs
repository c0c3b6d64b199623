//! The one error type of the library.
//!
//! Every variant carries the data a user needs to fix the input: what was
//! expected, what came, and where (line, column, field, file index).

use std::fmt;

/// Result alias used throughout the crate.
pub type Result<T> = std::result::Result<T, Error>;

/// Everything that can go wrong in robocal, with enough context to act on.
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// The bytes are not an image in a supported format, or decoding failed.
    Image {
        /// What went wrong, in plain words.
        message: String,
    },
    /// Text input (pose file, CSV, JSON) could not be parsed.
    Parse {
        /// 1-based line number, 0 when the position is unknown.
        line: usize,
        /// 1-based column (field) number, 0 when the position is unknown.
        column: usize,
        /// What was expected and what came.
        message: String,
    },
    /// Fewer items than a method needs (views, points, poses, heights).
    TooFew {
        /// What is counted ("views", "point pairs", ...).
        what: String,
        /// The minimum the method needs.
        required: usize,
        /// How many were given.
        actual: usize,
    },
    /// The data is degenerate for the method (collinear points, parallel axes, ...).
    Degenerate {
        /// What is degenerate and what would fix it.
        message: String,
    },
    /// A value is outside its valid range or inconsistent with another.
    Invalid {
        /// The field or option concerned.
        field: String,
        /// What was expected and what came.
        message: String,
    },
    /// A target (board, grid, circle) was not found in an image.
    NotFound {
        /// Why, with counts where known ("found 48 of 54 corners ...").
        message: String,
    },
    /// An iterative method did not converge.
    NoConvergence {
        /// The method and what it reached.
        message: String,
    },
}

impl Error {
    /// Shorthand for [`Error::Invalid`].
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::Parse`].
    pub fn parse(line: usize, column: usize, message: impl Into<String>) -> Self {
        Error::Parse {
            line,
            column,
            message: message.into(),
        }
    }

    /// Shorthand for [`Error::TooFew`].
    pub fn too_few(what: impl Into<String>, required: usize, actual: usize) -> Self {
        Error::TooFew {
            what: what.into(),
            required,
            actual,
        }
    }

    /// Shorthand for [`Error::Degenerate`].
    pub fn degenerate(message: impl Into<String>) -> Self {
        Error::Degenerate {
            message: message.into(),
        }
    }

    /// A short machine-readable name of the variant, used in JSON error objects.
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Image { .. } => "image",
            Error::Parse { .. } => "parse",
            Error::TooFew { .. } => "too_few",
            Error::Degenerate { .. } => "degenerate",
            Error::Invalid { .. } => "invalid",
            Error::NotFound { .. } => "not_found",
            Error::NoConvergence { .. } => "no_convergence",
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Image { message } => write!(f, "{message}"),
            Error::Parse {
                line,
                column,
                message,
            } => match (line, column) {
                (0, _) => write!(f, "{message}"),
                (l, 0) => write!(f, "line {l}: {message}"),
                (l, c) => write!(f, "line {l}, column {c}: {message}"),
            },
            Error::TooFew {
                what,
                required,
                actual,
            } => {
                write!(f, "requires at least {required} {what}, got {actual}")
            }
            Error::Degenerate { message } => write!(f, "{message}"),
            Error::Invalid { field, message } => write!(f, "{field}: {message}"),
            Error::NotFound { message } => write!(f, "{message}"),
            Error::NoConvergence { message } => write!(f, "{message}"),
        }
    }
}

impl std::error::Error for Error {}

/// Numbers beyond this magnitude (or below its inverse squared, 1e-12) are
/// written in scientific notation by [`compact`].
const COMPACT_LIMIT: f64 = 1e6;

/// A number for a human message: as Rust prints it between 1e-12 and a
/// million (`0.5`, `-30`), in scientific notation beyond (`1e308`, not 309
/// digits; `-2.5e-20`).
pub fn compact(x: f64) -> String {
    let a = x.abs();
    if x.is_finite()
        && a != 0.0
        && !(1.0 / (COMPACT_LIMIT * COMPACT_LIMIT)..COMPACT_LIMIT).contains(&a)
    {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// `n` as an English ordinal: 1st, 2nd, 3rd, 4th, 11th, 12th, 13th, 21st.
pub fn ordinal(n: usize) -> String {
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn messages_say_where_and_what() {
        assert_eq!(
            Error::parse(7, 5, "'abc' is not a number").to_string(),
            "line 7, column 5: 'abc' is not a number"
        );
        assert_eq!(
            Error::parse(3, 0, "6 values").to_string(),
            "line 3: 6 values"
        );
        assert_eq!(
            Error::too_few("views", 3, 1).to_string(),
            "requires at least 3 views, got 1"
        );
        assert_eq!(Error::too_few("views", 3, 1).kind(), "too_few");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn numbers_in_messages_stay_short() {
        assert_eq!(compact(1e308), "1e308");
        assert_eq!(compact(-2.5e-20), "-2.5e-20");
        assert_eq!(compact(1e6), "1e6");
        assert_eq!(compact(999999.5), "999999.5");
        assert_eq!(compact(-30.0), "-30");
        assert_eq!(compact(0.0), "0");
        assert_eq!(compact(f64::NAN), "NaN");
        assert_eq!(compact(f64::NEG_INFINITY), "-inf");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn ordinals_have_their_english_suffix() {
        let got: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22, 23, 100, 101, 111, 112]
            .into_iter()
            .map(ordinal)
            .collect();
        assert_eq!(
            got,
            [
                "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "23rd",
                "100th", "101st", "111th", "112th"
            ]
        );
    }
}
