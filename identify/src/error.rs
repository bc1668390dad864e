//! Typed errors of the identification stage.
//!
//! A fit that cannot identify its law returns one of these instead of numbers: too few points,
//! non-finite values, zero variance, negative pressure, a scale parameter (`I₀`, `V*`, `δ`)
//! outside the range of its variable in the data, a parameter ending at its bound, a 95 %
//! interval crossing a physical bound, a parameter whose standard error exceeds its value, an R²
//! below [`crate::accept::MIN_R_SQUARED`] or below that of the law's simpler nested form, a
//! rank-deficient Jacobian (the checks are in [`crate::accept`]). Where a simpler form is
//! supported, the refusal carries it as a [`Suggestion`] that ends its message
//! (`…; use mu-i-linear`). [`IdentifyError::is_refusal`] tells a refused fit (the data were
//! valid) from bad input. Reading a user's CSV gives errors that name the file, the line and
//! the column. Computed numbers in messages are printed short ([`short`]).

use crate::report::FitReport;
use crate::stats::min_max;

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

/// A simpler form to offer in a refusal (`use mu-i-linear`, `fix the cohesion at zero with
/// '# cohesion = 0'`); shown as `; {text}` at the end of the message, nothing when empty.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Suggestion(Option<Box<str>>);

impl Suggestion {
    /// No suggestion.
    pub fn none() -> Self {
        Suggestion(None)
    }

    /// A suggestion with this text.
    pub fn of(text: &str) -> Self {
        Suggestion(Some(text.into()))
    }

    /// The text, if any.
    pub fn text(&self) -> Option<&str> {
        self.0.as_deref()
    }
}

impl std::fmt::Display for Suggestion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            Some(s) => write!(f, "; {s}"),
            None => Ok(()),
        }
    }
}

/// Where a scale parameter lies with respect to the data range of its variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScaleSide {
    /// Above the largest value in the data.
    AboveData,
    /// Below the smallest (positive) value in the data.
    BelowData,
}

impl std::fmt::Display for ScaleSide {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ScaleSide::AboveData => write!(f, "above the largest"),
            ScaleSide::BelowData => write!(f, "below the smallest"),
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
    /// A scale parameter of the law (`I₀` of μ(I), `V*` of a wall law, `δ` of a boundary layer)
    /// lies outside the range of its variable in the data, `[x_min⁺, x_max]` (`x_min⁺` the
    /// smallest positive value): the law's curvature is not seen, the scale and the asymptote on
    /// that side are not separately identifiable from these data (criterion of
    /// [`crate::accept::check_scale`]).
    #[error("{law}: refused: {parameter} = {v} lies {side} {variable} in the data ({edge}, data range [{lo}, {hi}]): {parameter} and the law's asymptote are not separately identifiable{suggestion}",
        v = short(*.value), edge = short(match .side { ScaleSide::AboveData => *.data_max, ScaleSide::BelowData => *.data_min }),
        lo = short(*.data_min), hi = short(*.data_max))]
    ScaleNotResolved {
        /// Law or fit.
        law: String,
        /// Parameter name.
        parameter: String,
        /// Its estimate.
        value: f64,
        /// The variable it is a scale of (`I`, `V`, `y`).
        variable: String,
        /// Which side of the data it lies on.
        side: ScaleSide,
        /// Smallest positive value of the variable.
        data_min: f64,
        /// Largest value of the variable.
        data_max: f64,
        /// A simpler form the data support, if any.
        suggestion: Suggestion,
    },
    /// A parameter ended on a bound of its admissible box. The constrained fit is attached so the
    /// caller can inspect it, but its numbers are not an estimate with a valid interval.
    /// The message shows `bound` and `value` with six significant digits ([`short`]).
    #[error("parameter {name} ended at its {side} bound {b} (value {v}): the data push it outside its physical range{suggestion}", b = short(*.bound), v = short(*.value))]
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
        /// A simpler form the data support, if any.
        suggestion: Suggestion,
    },
    /// A parameter the law's shape rests on is not determined by the data: its standard error
    /// exceeds its magnitude, `se(θ) > |θ|`, so its confidence interval `θ ∓ t·se` spans zero
    /// and reaches beyond it by more than `(t − 1)|θ|` (`t ≈ 2–2.8` at 95 %): not even the
    /// sign or order of magnitude of `θ` is fixed (criterion of
    /// [`crate::accept::check_identified`]). The fit is attached for inspection only.
    #[error("{law}: not identifiable: {name} = {v} has standard error {se} > |{name}|, its {level} % CI [{lo}, {hi}] spans zero: the data do not determine it{suggestion}",
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
        /// A simpler form the data support, if any.
        suggestion: Suggestion,
    },
    /// The confidence interval of a parameter reaches beyond its physical range (`I₀ < 0`,
    /// `c < 0`, `φ_min < 0`, `μ_w > μ_wall`, ...): the data do not exclude unphysical values, so
    /// the interval is not a statement about the material (criterion of
    /// [`crate::accept::check_physical_ranges`]). The fit is attached for inspection only.
    #[error("{law}: refused: the {level} % interval of {name} [{lo}, {hi}] crosses its physical {side} bound {b}{suggestion}",
        level = short(100.0 * *.confidence), lo = short(*.ci_low), hi = short(*.ci_high), b = short(*.bound))]
    IntervalCrossesBound {
        /// Law or fit.
        law: String,
        /// Parameter name.
        name: String,
        /// Its estimate.
        value: f64,
        /// Lower end of its interval.
        ci_low: f64,
        /// Upper end of its interval.
        ci_high: f64,
        /// The physical bound crossed.
        bound: f64,
        /// Which bound.
        side: BoundSide,
        /// Confidence level.
        confidence: f64,
        /// The fit, for inspection only.
        report: Box<FitReport>,
        /// A simpler form the data support, if any.
        suggestion: Suggestion,
    },
    /// The law explains too little of the data's variance: `R²` below the threshold
    /// ([`crate::accept::MIN_R_SQUARED`] by default, [`crate::FitOptions::min_r_squared`]).
    #[error("{law}: refused: R² = {r2} is below {min}: the law does not describe these data{suggestion}",
        r2 = short(*.r_squared), min = short(*.threshold))]
    RSquaredTooLow {
        /// Law or fit.
        law: String,
        /// R² of the fit.
        r_squared: f64,
        /// The threshold.
        threshold: f64,
        /// The fit, for inspection only.
        report: Box<FitReport>,
        /// A simpler form, if any.
        suggestion: Suggestion,
    },
    /// The law does no better than its simpler nested form on these data: its adjusted
    /// `R̄² = 1 − (1 − R²)(n − 1)/(n − p)` is below the nested form's, so its extra parameters
    /// are not supported (criterion of [`crate::accept::check_nested`]).
    #[error("{law}: refused: adjusted R² = {a} is below {b} of its simpler nested form {nested}: the extra parameters are not supported by the data{suggestion}",
        a = short(*.adjusted_r_squared), b = short(*.nested_adjusted_r_squared))]
    WorseThanNested {
        /// Law or fit.
        law: String,
        /// Its adjusted R².
        adjusted_r_squared: f64,
        /// The nested form (`mu-i-linear`, `janssen with full mobilisation`, ...).
        nested: String,
        /// The nested form's adjusted R².
        nested_adjusted_r_squared: f64,
        /// The fit, for inspection only.
        report: Box<FitReport>,
        /// The simpler form to use.
        suggestion: Suggestion,
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
    #[error("{file}: missing column '{column}' (header has: {available}){hint}")]
    MissingColumn {
        /// File name.
        file: String,
        /// Required column.
        column: String,
        /// The header's columns, comma separated.
        available: String,
        /// What to rename when the column is there in a unit that is not read.
        hint: Suggestion,
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
    /// A `# key = value` line whose key the law does not read: refused rather than ignored, so
    /// that a misspelt key never leaves a default in place.
    #[error("{file}:{line}: unknown metadata key '{key}' for {law} (known keys: {known})")]
    UnknownMetadata {
        /// File name.
        file: String,
        /// 1-based line (0 for a key given by the caller's options).
        line: u64,
        /// The key.
        key: String,
        /// The law being fitted.
        law: String,
        /// The keys the law reads, comma separated.
        known: String,
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
        "calibrated law schema version {found} is not supported (this build reads versions 1 to {supported})"
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

impl IdentifyError {
    /// True when the data were valid for the law but the fit was refused: not identifiable, a
    /// parameter at its bound or not determined, an interval crossing a physical bound, a scale
    /// outside the data, an R² too low or below the nested form's, no convergence, zero variance
    /// of a column. False for bad input (unreadable or malformed file, missing column or
    /// metadata, value out of its domain, too few rows, unknown law or key). `grainlaw fit`
    /// exits with 3 for a refusal and 2 for bad input.
    pub fn is_refusal(&self) -> bool {
        matches!(
            self,
            IdentifyError::ZeroVariance { .. }
                | IdentifyError::ScaleNotResolved { .. }
                | IdentifyError::ParameterAtBound { .. }
                | IdentifyError::ParameterNotIdentified { .. }
                | IdentifyError::IntervalCrossesBound { .. }
                | IdentifyError::RSquaredTooLow { .. }
                | IdentifyError::WorseThanNested { .. }
                | IdentifyError::NotIdentifiable { .. }
                | IdentifyError::NoConvergence { .. }
                | IdentifyError::ConicSolver { .. }
        )
    }

    /// The simpler form the refusal offers, if any.
    pub fn suggestion(&self) -> Option<&str> {
        match self {
            IdentifyError::ScaleNotResolved { suggestion, .. }
            | IdentifyError::ParameterAtBound { suggestion, .. }
            | IdentifyError::ParameterNotIdentified { suggestion, .. }
            | IdentifyError::IntervalCrossesBound { suggestion, .. }
            | IdentifyError::RSquaredTooLow { suggestion, .. }
            | IdentifyError::WorseThanNested { suggestion, .. } => suggestion.text(),
            _ => None,
        }
    }

    /// The same error offering `text` as the simpler form, when it is a refusal that carries a
    /// suggestion and has none yet (other errors are returned unchanged).
    pub fn suggesting(mut self, text: &str) -> Self {
        match &mut self {
            IdentifyError::ScaleNotResolved { suggestion, .. }
            | IdentifyError::ParameterAtBound { suggestion, .. }
            | IdentifyError::ParameterNotIdentified { suggestion, .. }
            | IdentifyError::IntervalCrossesBound { suggestion, .. }
            | IdentifyError::RSquaredTooLow { suggestion, .. }
            | IdentifyError::WorseThanNested { suggestion, .. }
                if suggestion.text().is_none() =>
            {
                *suggestion = Suggestion::of(text);
            }
            _ => {}
        }
        self
    }
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
