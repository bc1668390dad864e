//! Typed errors of the identification stage.
//!
//! A fit that cannot identify its law returns one of these instead of numbers: too few points,
//! non-finite values, zero variance, negative pressure, an inertial-number range far below (or
//! above) `I₀`, a parameter ending at its bound, a parameter whose standard error exceeds its
//! value, a rank-deficient Jacobian. Reading a user's CSV gives errors that name the file, the
//! line and the column. Computed numbers in messages are printed short ([`short`]).

use crate::report::FitReport;

/// Which side of a box constraint a parameter ended on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoundSide {
    /// The lower bound.
    Lower,
    /// The upper bound.
    Upper,
}

impl std::fmt::Display for BoundSide {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BoundSide::Lower => write!(f, "lower"),
            BoundSide::Upper => write!(f, "upper"),
        }
    }
}

/// Every way identification can fail.
#[derive(Debug, thiserror::Error)]
pub enum IdentifyError {
    /// Fewer observations than the law needs (parameters + 2, so that the residual variance has
    /// at least two degrees of freedom).
    #[error("{law}: too few points: {got} given, at least {needed} needed")]
    TooFewPoints {
        /// Law or fit being attempted.
        law: String,
        /// Minimum number of points.
        needed: usize,
        /// Number of points given.
        got: usize,
    },
    /// A value is NaN or infinite.
    #[error("{column}[{index}] is not finite ({value})")]
    NonFinite {
        /// Column (quantity) name.
        column: String,
        /// 0-based index of the value in its column.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A column has no spread, so the law cannot be identified from it.
    #[error("{column} has zero variance (all values equal {value}): the law cannot be identified")]
    ZeroVariance {
        /// Column (quantity) name.
        column: String,
        /// The common value.
        value: f64,
    },
    /// A pressure-like quantity (compressive positive) is negative.
    #[error("negative pressure in {column}[{index}] = {value} Pa (inputs are compressive-positive magnitudes)")]
    NegativePressure {
        /// Column (quantity) name.
        column: String,
        /// 0-based index.
        index: usize,
        /// The offending value (Pa).
        value: f64,
    },
    /// A value outside the domain of its quantity (e.g. `I ≤ 0`, a depth below zero).
    #[error("{column}[{index}] = {value} is out of its domain: {expected}")]
    OutOfDomain {
        /// Column (quantity) name.
        column: String,
        /// 0-based index.
        index: usize,
        /// The offending value.
        value: f64,
        /// What was expected.
        expected: String,
    },
    /// Two columns that must pair up have different lengths.
    #[error("{first} has {first_len} values but {second} has {second_len}")]
    LengthMismatch {
        /// First column.
        first: String,
        /// Its length.
        first_len: usize,
        /// Second column.
        second: String,
        /// Its length.
        second_len: usize,
    },
    /// A set-up constant (width, density, wall friction, ...) is invalid.
    #[error("invalid {field} = {value}: {expected}")]
    InvalidSetup {
        /// Field name.
        field: String,
        /// Value given.
        value: f64,
        /// What is required.
        expected: String,
    },
    /// The depth window keeps too few depths.
    #[error("depth window [{z_min} m, {z_max} m] keeps {kept} of {total} depths")]
    EmptyDepthWindow {
        /// Window start (m).
        z_min: f64,
        /// Window end (m).
        z_max: f64,
        /// Depths kept.
        kept: usize,
        /// Depths given.
        total: usize,
    },
    /// All inertial numbers are far below `I₀` (`I_max < I₀/10`): only the slope
    /// `(μ₂ − μ_s)/I₀` is identified, not `μ₂` and `I₀` separately.
    #[error("all I ≤ {i_max:.3e} are far below I₀ ≈ {i0:.3e} (I_max < I₀/10): μ₂ and I₀ are not separately identifiable; fit the linear form or extend the I range")]
    IRangeBelowI0 {
        /// Largest inertial number in the data.
        i_max: f64,
        /// The estimate of `I₀` the fit ran to.
        i0: f64,
    },
    /// All inertial numbers are far above `I₀` (`I_min > 10 I₀`): the data sit on the plateau
    /// `μ ≈ μ₂` and `μ_s` is not identified.
    #[error("all I ≥ {i_min:.3e} are far above I₀ ≈ {i0:.3e} (I_min > 10 I₀): μ_s is not identifiable; extend the I range to slower flows")]
    IRangeAboveI0 {
        /// Smallest inertial number in the data.
        i_min: f64,
        /// The estimate of `I₀` the fit ran to.
        i0: f64,
    },
    /// A characteristic scale of the law (`V*`, `δ`, ...) lies far outside the data range,
    /// so the law's curvature is not seen by the data.
    #[error("{parameter} = {value:.3e} lies far outside the data range [{data_min:.3e}, {data_max:.3e}]: not identifiable from these data")]
    ScaleNotResolved {
        /// Parameter name.
        parameter: String,
        /// Its estimate.
        value: f64,
        /// Smallest abscissa.
        data_min: f64,
        /// Largest abscissa.
        data_max: f64,
    },
    /// A parameter ended on a bound of its admissible box. The constrained fit is attached so the
    /// caller can inspect it, but its numbers are not an estimate with a valid interval.
    /// The message shows `bound` and `value` with six significant digits ([`short`]).
    #[error("parameter {name} ended at its {side} bound {b} (value {v}): the data push it outside its physical range", b = short(*.bound), v = short(*.value))]
    ParameterAtBound {
        /// Parameter name.
        name: String,
        /// Final value.
        value: f64,
        /// The bound it sits on.
        bound: f64,
        /// Which bound.
        side: BoundSide,
        /// The constrained fit, for inspection only.
        report: Box<FitReport>,
    },
    /// A parameter the law's shape rests on is not determined by the data: its standard error
    /// exceeds its magnitude, `se(θ) > |θ|`, so its confidence interval `θ ∓ t·se` spans zero
    /// and reaches beyond it by more than `(t − 1)|θ|` (`t ≈ 2–2.8` at 95 %): not even the
    /// sign or order of magnitude of `θ` is fixed (criterion of
    /// [`crate::fit::check_identified`]). The fit is attached for inspection only.
    #[error("{law}: not identifiable: {name} = {v} has standard error {se} > |{name}|, its {level} % CI [{lo}, {hi}] spans zero: the data do not determine it",
        v = short(*.value), se = short(*.std_error), level = short(100.0 * *.confidence),
        lo = short(*.ci_low), hi = short(*.ci_high))]
    ParameterNotIdentified {
        /// Law or fit (`wall-law-power`, ...).
        law: String,
        /// Parameter name.
        name: String,
        /// Its estimate.
        value: f64,
        /// Its standard error.
        std_error: f64,
        /// Lower end of its confidence interval.
        ci_low: f64,
        /// Upper end of its confidence interval.
        ci_high: f64,
        /// Confidence level of the interval (0.95 by default).
        confidence: f64,
        /// The fit, for inspection only.
        report: Box<FitReport>,
    },
    /// The Jacobian at the optimum is rank deficient (or the fit is otherwise degenerate).
    #[error("not identifiable: {reason}")]
    NotIdentifiable {
        /// Explanation.
        reason: String,
    },
    /// The optimiser did not converge.
    #[error("{solver} did not converge: {reason}")]
    NoConvergence {
        /// Solver name.
        solver: String,
        /// Why it stopped.
        reason: String,
    },
    /// The steady-flow problem has no solution (e.g. `tan θ` outside `(μ_s, μ₂)`).
    #[error("no steady flow: {reason}")]
    NoSteadyFlow {
        /// Explanation.
        reason: String,
    },
    /// A column required by the law is missing from a CSV header.
    #[error("{file}: missing column '{column}' (header has: {available})")]
    MissingColumn {
        /// File name.
        file: String,
        /// Required column.
        column: String,
        /// The header's columns, comma separated.
        available: String,
    },
    /// A CSV cell that should be a number is not.
    #[error("{file}:{line}: column '{column}': '{value}' is not a number")]
    NonNumericCell {
        /// File name.
        file: String,
        /// 1-based line number in the file.
        line: u64,
        /// Column header.
        column: String,
        /// Cell content.
        value: String,
    },
    /// A CSV number is NaN or infinite.
    #[error("{file}:{line}: column '{column}': value {value} is not finite")]
    NonFiniteCell {
        /// File name.
        file: String,
        /// 1-based line number.
        line: u64,
        /// Column header.
        column: String,
        /// The value.
        value: f64,
    },
    /// A `# key = value` metadata line required by the law is missing or malformed.
    #[error("{file}: {message}")]
    Metadata {
        /// File name.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// Malformed CSV (ragged rows, bad UTF-8, ...).
    #[error("{file}:{line}: {message}")]
    Csv {
        /// File name.
        file: String,
        /// 1-based line number (0 when unknown).
        line: u64,
        /// Parser message.
        message: String,
    },
    /// File could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// Underlying error.
        #[source]
        source: std::io::Error,
    },
    /// Calibrated-law JSON could not be parsed or is inconsistent.
    #[error("calibrated law JSON: {message}")]
    LawFormat {
        /// What is wrong.
        message: String,
    },
    /// Calibrated-law JSON of a schema version this build does not read.
    #[error(
        "calibrated law schema version {found} is not supported (this build reads {supported})"
    )]
    UnsupportedSchema {
        /// Version found.
        found: u32,
        /// Version supported.
        supported: u32,
    },
    /// Unknown law name.
    #[error("unknown law '{name}' (known: {known})")]
    UnknownLaw {
        /// Name given.
        name: String,
        /// Known names, comma separated.
        known: String,
    },
    /// The conic solver (Clarabel) did not return a solution.
    #[error("conic solver: {status}")]
    ConicSolver {
        /// Solver status.
        status: String,
    },
}

/// A number with six significant digits for messages (the `%g` of C): plain notation for
/// `10⁻⁴ ≤ |x| < 10⁶`, else `d.ddddde±x`; trailing zeros dropped. `0`, `10`, `1.5708`,
/// `9.9e-7`, `1.1897e-17`. Non-finite values as Rust prints them (`NaN`, `inf`).
pub fn short(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    // Round to six significant digits first, so that 9.9999999 becomes 10 (exponent 1).
    let e = format!("{x:.5e}");
    let (mantissa, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if (-4..6).contains(&exp) {
        let decimals = (5 - exp).max(0) as usize;
        trim_zeros(&format!("{x:.decimals$}"))
    } else {
        format!("{}e{exp}", trim_zeros(mantissa))
    }
}

/// Drops trailing zeros after a decimal point (and the point itself if nothing is left).
fn trim_zeros(s: &str) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s.to_string()
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, IdentifyError>;

/// Checks that every value of a column is finite.
pub(crate) fn check_finite(column: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(IdentifyError::NonFinite {
            column: column.to_string(),
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Checks that two columns have the same length.
pub(crate) fn check_same_len(first: &str, a: &[f64], second: &str, b: &[f64]) -> Result<()> {
    if a.len() != b.len() {
        return Err(IdentifyError::LengthMismatch {
            first: first.to_string(),
            first_len: a.len(),
            second: second.to_string(),
            second_len: b.len(),
        });
    }
    Ok(())
}

/// Checks that a column is not constant (relative spread above 1e-12).
pub(crate) fn check_spread(column: &str, values: &[f64]) -> Result<()> {
    let (lo, hi) = min_max(values);
    let scale = lo.abs().max(hi.abs());
    if values.is_empty() || hi - lo <= 1e-12 * scale || hi == lo {
        return Err(IdentifyError::ZeroVariance {
            column: column.to_string(),
            value: values.first().copied().unwrap_or(f64::NAN),
        });
    }
    Ok(())
}

/// Checks that a pressure-like column (compressive positive) has no negative value.
pub(crate) fn check_non_negative_pressure(column: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| *v < 0.0) {
        Some(index) => Err(IdentifyError::NegativePressure {
            column: column.to_string(),
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Checks a strictly positive, finite set-up constant.
pub(crate) fn check_setup_positive(field: &str, value: f64) -> Result<()> {
    if !(value.is_finite() && value > 0.0) {
        return Err(IdentifyError::InvalidSetup {
            field: field.to_string(),
            value,
            expected: "a finite, strictly positive number".to_string(),
        });
    }
    Ok(())
}

/// Smallest and largest value (`(+∞, −∞)` for an empty slice).
pub(crate) fn min_max(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn short_numbers_have_six_significant_digits() {
        assert_eq!(short(0.0), "0");
        assert_eq!(short(10.0), "10");
        assert_eq!(short(9.99999998), "10");
        assert_eq!(short(std::f64::consts::FRAC_PI_2), "1.5708");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(-0.01), "-0.01");
        assert_eq!(short(1.1897e-17), "1.1897e-17");
        assert_eq!(short(123456789.0), "1.23457e8");
        assert_eq!(short(0.000123), "0.000123");
        assert_eq!(short(f64::NAN), "NaN");
    }
}
