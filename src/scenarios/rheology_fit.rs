//! The μ(I) and φ(I) fits of a rheology (a shear cell's or a simple-shear RVE's points): the
//! fits (the full law, then its linear form when the data do not support it), their curves
//! and 95 % bands on the figures, the summary keys, the printed parameters with their
//! intervals, and the laws exported under their verdicts ([`crate::verdict::export_law`]).
//! One implementation for every scenario that measures μ(I) and φ(I).

use identify::law::{GrainScale, Provenance};
use identify::mu_i::{fit_mu_i, fit_mu_i_linear, fit_phi_i, RheologySeries};
use identify::{CalibratedLaw, FitOptions};

use super::common::{add_fitted_curve, delta_band, fit_keys, parameter_lines};
use crate::error::Result;
use crate::output::{OutputDir, Summary};
use crate::plot::xy::{Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::progress::warn;
use crate::verdict::{export_law, Checks, RunVerdict, Verdict};

/// What the fits of a rheology need besides its points.
pub(crate) struct RheologyFit<'a> {
    /// Prefix of the verdict's check names (`shear_cell`, `simple_shear`).
    pub(crate) check_prefix: &'a str,
    /// Appended to the figures' titles.
    pub(crate) title_suffix: &'a str,
    /// Legend of the measured points.
    pub(crate) dem_label: &'a str,
    /// The grains' scale, for the laws' constants.
    pub(crate) grain: GrainScale,
    /// Provenance of the laws.
    pub(crate) provenance: Provenance,
    /// The checks the μ(I) law depends on.
    pub(crate) mu_checks: Checks,
    /// The checks the φ(I) law depends on.
    pub(crate) phi_checks: Checks,
    /// The laws the plan leaves out (`mu-i`, `mu-i-linear`, `phi-i`): not fitted.
    pub(crate) leave_out: &'a [String],
}

/// How an accepted fit is shown: its summary-key prefix, the form recorded under
/// `{key}_form` (with `{key}_r_squared`), the formula (legend), the printed title and colour.
struct Shown {
    key: &'static str,
    form: Option<&'static str>,
    formula: &'static str,
    title: &'static str,
    colour: plotters::style::RGBColor,
}

impl Shown {
    /// The fitted curve with its 95 % band on `plot`, the summary keys, and the printed
    /// parameters with their intervals.
    fn record(
        &self,
        plot: &mut XyPlot,
        xs: &[f64],
        report: &identify::FitReport,
        s: &mut Summary,
        headline: &mut Vec<String>,
        model: impl Fn(&[f64], f64) -> f64,
    ) {
        let band = delta_band(
            &report.values(),
            &report.covariance,
            report.t_critical,
            xs,
            model,
        );
        add_fitted_curve(plot, self.formula, self.colour, PALETTE[1], &band);
        fit_keys(s, self.key, &report.parameters);
        if let Some(form) = self.form {
            s.text(&format!("{}_form", self.key), form)
                .num(&format!("{}_r_squared", self.key), report.r_squared);
        }
        headline.extend(parameter_lines(
            self.title,
            report.r_squared,
            &report.parameters,
        ));
    }
}

/// Fits μ(I) and φ(I) to `series` (those the plan does not leave out), writes the laws that
/// pass (or their `.rejected.json`), records refusals in `verdict`, the keys in `s`, the printed
/// lines in `headline`; returns the μ(I) and φ(I) figures.
pub(crate) fn fit_mu_phi(
    out: &mut OutputDir,
    series: &RheologySeries,
    inp: &RheologyFit<'_>,
    verdict: &mut RunVerdict,
    s: &mut Summary,
    headline: &mut Vec<String>,
) -> Result<(XyPlot, XyPlot)> {
    let opts = FitOptions::default();
    let is = &series.inertial_number;
    let points = |ys: Option<&[f64]>| -> Vec<(f64, f64)> {
        ys.map(|ys| is.iter().copied().zip(ys.iter().copied()).collect())
            .unwrap_or_default()
    };
    let (imin, imax) = (
        is.iter().cloned().fold(f64::MAX, f64::min),
        is.iter().cloned().fold(f64::MIN, f64::max),
    );
    let xs: Vec<f64> = (0..=80)
        .map(|k| imin * 0.7 * (imax * 1.4 / (imin * 0.7)).powf(k as f64 / 80.0))
        .collect();
    let mut pmu = XyPlot::new(
        &format!("Friction law μ(I){}", inp.title_suffix),
        Axis::new("inertial number I").log(),
        Axis::new("μ = |σ_xy| / P"),
    );
    pmu.series.push(Series::new(
        inp.dem_label,
        Style::Points,
        PALETTE[0],
        points(series.mu.as_deref()),
    ));
    let left = |law: &str| inp.leave_out.iter().any(|l| l == law);
    // μ(I), or its linear form when μ(I) is refused or left out (`leave_out`)
    let full = if left("mu-i") {
        None
    } else {
        Some(fit_mu_i(series, &opts))
    };
    let linear_reason = match full {
        Some(Ok(f)) => {
            let shown = Shown {
                key: "mu_i",
                form: Some("mu-i"),
                formula: "μ_s + (μ₂ − μ_s)/(1 + I₀/I)",
                title: "μ(I) = μ_s + (μ₂ − μ_s)/(1 + I₀/I)",
                colour: PALETTE[0],
            };
            shown.record(&mut pmu, &xs, &f.report, s, headline, |p, i| {
                identify::laws::mu_i::MuILaw {
                    mu_s: p[0],
                    mu_2: p[1],
                    i0: p[2],
                }
                .mu(i)
            });
            export_law(
                out,
                verdict,
                "mu_i",
                &CalibratedLaw::from_mu_i(&f, inp.grain, inp.provenance.clone()),
                inp.mu_checks.clone(),
            )?;
            None
        }
        Some(Err(e)) => {
            s.text("mu_i_fit_error", &e.to_string());
            Some(e.to_string())
        }
        None => None,
    };
    let try_linear = linear_reason.is_some() || left("mu-i");
    if try_linear && left("mu-i-linear") {
        // neither form is fitted: the plan said so at the start
        crate::verdict::remove_stale_law(out, "mu_i")?;
        if let Some(e) = linear_reason {
            warn(&format!(
                "μ(I) fit failed ({e}); its linear form is left out (leave_out)"
            ));
            verdict.run.fail(
                &format!("{}.mu_i_fit", inp.check_prefix),
                Verdict::Refused,
                f64::NAN,
                f64::NAN,
                format!("no μ(I) law could be fitted: {e}"),
            );
        }
    } else if try_linear {
        if let Some(e) = &linear_reason {
            warn(&format!(
                "μ(I) fit failed ({e}); fitting the linear form μ_s + b I"
            ));
        }
        match fit_mu_i_linear(series, &opts) {
            Ok(f) => {
                let shown = Shown {
                    key: "mu_i",
                    form: Some("mu-i-linear"),
                    formula: "μ_s + b I",
                    title: "μ(I) = μ_s + b I (linear form)",
                    colour: PALETTE[0],
                };
                shown.record(&mut pmu, &xs, &f.report, s, headline, |p, i| {
                    p[0] + p[1] * i
                });
                export_law(
                    out,
                    verdict,
                    "mu_i",
                    &CalibratedLaw::from_mu_i_linear(&f, inp.grain, inp.provenance.clone()),
                    inp.mu_checks.clone(),
                )?;
            }
            Err(e2) => {
                warn(&format!("linear μ(I) fit failed too: {e2}"));
                s.text("mu_i_linear_fit_error", &e2.to_string());
                crate::verdict::remove_stale_law(out, "mu_i")?;
                verdict.run.fail(
                    &format!("{}.mu_i_fit", inp.check_prefix),
                    Verdict::Refused,
                    f64::NAN,
                    f64::NAN,
                    format!("no μ(I) law could be fitted: {e2}"),
                );
            }
        }
    }
    pmu.legend = LegendAt::UpperLeft;
    let mut pphi = XyPlot::new(
        &format!("Solid fraction φ(I){}", inp.title_suffix),
        Axis::new("inertial number I").log(),
        Axis::new("solid fraction φ"),
    );
    pphi.series.push(Series::new(
        inp.dem_label,
        Style::Points,
        PALETTE[2],
        points(series.phi.as_deref()),
    ));
    match (!left("phi-i")).then(|| fit_phi_i(series, &opts)) {
        // left out by the plan (said at the start)
        None => crate::verdict::remove_stale_law(out, "phi_i")?,
        Some(Ok(f)) => {
            let shown = Shown {
                key: "phi_i",
                form: None,
                formula: "φ_max − a I",
                title: "φ(I) = φ_max − a I",
                colour: PALETTE[2],
            };
            shown.record(&mut pphi, &xs, &f.report, s, headline, |p, i| {
                p[0] - p[1] * i
            });
            export_law(
                out,
                verdict,
                "phi_i",
                &CalibratedLaw::from_phi_i(&f, inp.grain, inp.provenance.clone()),
                inp.phi_checks.clone(),
            )?;
        }
        Some(Err(e)) => {
            warn(&format!("φ(I) fit failed: {e}"));
            s.text("phi_i_fit_error", &e.to_string());
            crate::verdict::remove_stale_law(out, "phi_i")?;
            verdict.run.fail(
                &format!("{}.phi_i_fit", inp.check_prefix),
                Verdict::Refused,
                f64::NAN,
                f64::NAN,
                format!("the φ(I) fit failed: {e}"),
            );
        }
    }
    pphi.legend = LegendAt::UpperRight;
    Ok((pmu, pphi))
}
