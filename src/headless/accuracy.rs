//! `slidebase accuracy`: error against run time (work-precision) of the DDA model, against
//! exact references, over time step, integrator, penalty stiffness and ground model.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::frame::{run_frame, run_mdof};
use super::simulate::{self, ModelRun};
use crate::Result;
use crate::dda::{ContactEnforcement, Integrator, SolverParams};
use crate::model::scene::GroundKind;
use crate::post::output::Staged;
use crate::post::plot::{Figure, Series};
use crate::setup::{ExcitationSpec, HistoryPlan, RunSpec};

/// One run of the study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AccuracyRow {
    /// `timestep`, `penalty`, `ground`, `fixed-base` or `three-storey`.
    pub study: String,
    /// The physical case.
    pub case: String,
    /// Integrator label.
    pub integrator: String,
    /// Time step, s.
    pub dt: f64,
    /// Normal penalty of the joint, N/m (shear = normal / 2.5).
    pub penalty: f64,
    /// `prescribed` or `large-mass:<ratio>`.
    pub ground: String,
    /// Wall-clock time, s.
    pub wall_time_s: f64,
    /// Steps.
    pub steps: u64,
    /// Largest relative error of the paper's four peak metrics (floor 0.01).
    pub peak_error: f64,
    /// RMS error of the slip history / D (two-block) or of the quantity studied.
    pub rms_slip: f64,
    /// RMS error of the roof drift history / D.
    pub rms_drift: f64,
    /// RMS error of the slip history / D (the drift's for a fixed base) against the
    /// Δt-converged DDA run of the same case (self-convergence: what the time step alone
    /// costs); NaN where not computed.
    pub rms_slip_self: f64,
    /// Relative error of the base acceleration peak.
    pub abase_error: f64,
}

/// Young's modulus of the two-block scene's (practically rigid) blocks, Pa: the penalty
/// axis is also given relative to it.
const BLOCK_E: f64 = 1e12;

/// A two-block case of the study.
#[derive(Debug, Clone, Copy)]
struct Case {
    name: &'static str,
    alpha: f64,
    friction: f64,
    ratio: f64,
}

const CASES: [Case; 6] = [
    Case {
        name: "resonant α=0.5 ρ=0.1 Ω/ω=1",
        alpha: 0.5,
        friction: 0.1,
        ratio: 1.0,
    },
    Case {
        name: "low Ω/ω=0.3, light raft α=0.9, ρ=0.05",
        alpha: 0.9,
        friction: 0.05,
        ratio: 0.3,
    },
    Case {
        name: "high Ω/ω=5, heavy raft α=0.1, ρ=0.25",
        alpha: 0.1,
        friction: 0.25,
        ratio: 5.0,
    },
    Case {
        name: "low ρ=0.01, α=0.5, Ω/ω=2",
        alpha: 0.5,
        friction: 0.01,
        ratio: 2.0,
    },
    Case {
        name: "high ρ=0.25, α=0.5, Ω/ω=0.7",
        alpha: 0.5,
        friction: 0.25,
        ratio: 0.7,
    },
    Case {
        name: "sticky ρ=0.25, α=0.9, Ω/ω=1.5",
        alpha: 0.9,
        friction: 0.25,
        ratio: 1.5,
    },
];

/// Integrators compared.
pub fn integrators() -> Vec<Integrator> {
    vec![
        Integrator::Classic,
        Integrator::Trapezoidal,
        Integrator::Hht { alpha: 0.1 },
        Integrator::GeneralizedAlpha { rho_inf: 0.5 },
        Integrator::GeneralizedAlpha { rho_inf: 0.0 },
    ]
}

/// Linear interpolation of (t, y) at `at`.
fn interp(t: &[f64], y: &[f64], at: f64) -> f64 {
    let k = t.partition_point(|&x| x < at);
    if k == 0 {
        return y.first().copied().unwrap_or(0.0);
    }
    if k >= t.len() {
        return y.last().copied().unwrap_or(0.0);
    }
    let w = (at - t[k - 1]) / (t[k] - t[k - 1]).max(f64::MIN_POSITIVE);
    y[k - 1] * (1.0 - w) + y[k] * w
}

/// RMS over the reference's times of (run − reference) for one history column.
fn rms(run: &ModelRun, reference: &ModelRun, column: &str) -> f64 {
    let (Some(t), Some(y)) = (run.history.column("time_s"), run.history.column(column)) else {
        return f64::NAN;
    };
    let (Some(tr), Some(yr)) = (
        reference.history.column("time_s"),
        reference.history.column(column),
    ) else {
        return f64::NAN;
    };
    let n = tr.len().max(1) as f64;
    (tr.iter()
        .zip(yr)
        .map(|(&ti, &yi)| (interp(t, y, ti) - yi).powi(2))
        .sum::<f64>()
        / n)
        .sqrt()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(0.01)
}

/// The integrator the two-block scene asks for (its runs' default).
fn two_block_integrator() -> Result<Integrator> {
    Ok(crate::setup::RunSpec::default().prepare()?.integrator)
}

/// The DDA two-block run of a case with these numerical settings, and the errors against
/// the exact solution.
#[allow(clippy::too_many_arguments)]
fn two_block_row(
    study: &str,
    case: &Case,
    duration: f64,
    integrator: Integrator,
    dt: f64,
    penalty: Option<f64>,
    ground: Option<(GroundKind, f64)>,
    fixed_base: bool,
    reference: &ModelRun,
    converged: Option<&ModelRun>,
) -> Result<AccuracyRow> {
    let spec = RunSpec {
        integrator: Some(integrator),
        ..case_spec(case, duration, dt, fixed_base)
    };
    let mut setup = spec.prepare()?;
    setup.history = HistoryPlan::EverySteps(record_every(dt));
    if let Some(p) = penalty {
        for c in setup.scene.contacts.iter_mut() {
            c.normal_penalty = Some(p);
            c.shear_penalty = Some(p / 2.5);
        }
    }
    if let Some((kind, ratio)) = ground {
        setup.scene.ground.kind = kind;
        setup.scene.ground.mass_ratio = ratio;
    }
    let penalty_used = setup
        .scene
        .contacts
        .first()
        .and_then(|c| c.normal_penalty)
        .unwrap_or(f64::NAN);
    // The penalty study is about the penalty springs: with the default exact constraints
    // their stiffness only sets how fast the multipliers converge.
    let contact_enforcement = if penalty.is_some() {
        ContactEnforcement::Penalty
    } else {
        ContactEnforcement::default()
    };
    let params = SolverParams {
        dt,
        duration,
        integrator,
        contact_enforcement,
        ..SolverParams::default()
    };
    let start = Instant::now();
    let run = simulate::run_dda(&setup, &setup.scene, params)?;
    let wall = start.elapsed().as_secs_f64();
    let a = setup.motion.peak_accel(duration);
    let structure_hz = setup
        .two_block()
        .map_or(f64::NAN, |(roles, _, _)| roles.structure_frequency_hz);
    let big_omega = 2.0 * std::f64::consts::PI * case.ratio * structure_hz;
    let d = a / (big_omega * big_omega);
    let metrics = |r: &ModelRun| {
        [
            r.peaks.slip_m / d,
            r.peaks.drift_m / d,
            r.peaks.base_accel / a,
            r.peaks.roof_accel / a,
        ]
    };
    let (m, mr) = (metrics(&run), metrics(reference));
    let peak_error = (0..4)
        .filter(|&k| !(fixed_base && k == 0))
        .map(|k| rel(m[k], mr[k]))
        .fold(0.0, f64::max);
    Ok(AccuracyRow {
        study: study.into(),
        case: case.name.into(),
        integrator: integrator.label(),
        dt,
        penalty: penalty_used,
        ground: match ground {
            Some((GroundKind::LargeMass, r)) => format!("large-mass:{r:e}"),
            _ => "prescribed".into(),
        },
        wall_time_s: wall,
        steps: run.steps,
        peak_error,
        rms_slip: rms(&run, reference, "slip_m") / d,
        rms_drift: rms(&run, reference, "roof_drift_m") / d,
        rms_slip_self: converged.map_or(f64::NAN, |c| {
            // A fixed base does not slip: its self-convergence is measured on the drift.
            let column = if fixed_base { "roof_drift_m" } else { "slip_m" };
            rms(&run, c, column) / d
        }),
        abase_error: rel(m[2], mr[2]),
    })
}

/// The run specification of a case (default integrator).
fn case_spec(case: &Case, duration: f64, dt: f64, fixed_base: bool) -> RunSpec {
    RunSpec {
        alpha: Some(case.alpha),
        friction: (!fixed_base).then_some(case.friction),
        excitation: ExcitationSpec::ratio(case.ratio),
        duration: Some(duration),
        dt: Some(dt),
        fixed_base,
        ..RunSpec::default()
    }
}

/// Histories are compared every 0.05 ms: linear interpolation between samples h apart
/// errs by ~h²·ü/8, 7e-7 D at 0.5 ms (measured: it was the study's RMS floor, hiding the
/// schemes' second order below Δt = 0.3 ms) and so ~7e-9 D here, below the finest
/// step's error.
const SAMPLE_DT: f64 = 5e-5;

fn record_every(dt: f64) -> usize {
    ((SAMPLE_DT / dt).round() as usize).max(1)
}

/// The DDA run of a case at the finest time step, to measure what the time step alone
/// costs: as Δt → 0 every scheme tends to it, and it differs from the exact mass-spring
/// solution only by the model (the blocks' and the joint's elasticity). The trapezoidal
/// rule, whose error constant is the smallest of the family: with ρ∞ = 0 (20× larger)
/// this reference's own error, 1e-7 D in RMS slip, was the floor of every scheme's.
fn converged_dda(case: &Case, duration: f64, dt: f64, fixed_base: bool) -> Result<ModelRun> {
    let mut setup = case_spec(case, duration, dt, fixed_base).prepare()?;
    setup.history = HistoryPlan::EverySteps(record_every(dt));
    let params = SolverParams {
        dt,
        duration,
        integrator: Integrator::Trapezoidal,
        ..SolverParams::default()
    };
    simulate::run_dda(&setup, &setup.scene, params)
}

fn exact_reference(case: &Case, duration: f64, fixed_base: bool) -> Result<ModelRun> {
    let spec = RunSpec {
        dt: None,
        ..case_spec(case, duration, crate::setup::defaults::DT, fixed_base)
    };
    simulate::run_exact_two_block(&spec.prepare()?, SAMPLE_DT)
}

/// Runs the study; `tick(done, total)` reports progress.
pub fn run_accuracy(quick: bool, tick: &dyn Fn(usize, usize)) -> Result<Vec<AccuracyRow>> {
    let mut rows = Vec::new();
    let duration = if quick { 4.0 } else { 10.0 };
    let cases: Vec<Case> = if quick {
        CASES[..2].to_vec()
    } else {
        CASES.to_vec()
    };
    let dts: Vec<f64> = if quick {
        vec![1e-2, 3e-3, 1e-3]
    } else {
        vec![1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5]
    };
    let integrators = if quick {
        vec![
            Integrator::Classic,
            Integrator::Trapezoidal,
            Integrator::GeneralizedAlpha { rho_inf: 0.0 },
        ]
    } else {
        integrators()
    };
    let penalties: Vec<f64> = if quick {
        vec![1e9, 1e11]
    } else {
        // 1e-3 to 1e4 × the blocks' E (1e12 Pa): from a soft joint to far stiffer than
        // the blocks.
        vec![1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e16]
    };
    let ratios: Vec<f64> = if quick {
        vec![1e2, 1e4]
    } else {
        vec![1e2, 1e3, 1e4, 1e6, 1e8]
    };
    let total = cases.len() * dts.len() * integrators.len()
        + penalties.len()
        + ratios.len()
        + 1
        + 2 * dts.len().min(4) * integrators.len()
        + if quick { 0 } else { 8 };
    let mut done = 0;
    let mut bump = |rows: &mut Vec<AccuracyRow>, r: AccuracyRow| {
        rows.push(r);
        done += 1;
        tick(done, total);
    };
    // 1. Time step × integrator on the two-block cases, all over the same window, against
    //    the exact solution and against the Δt-converged DDA run.
    let finest = dts.iter().copied().fold(f64::INFINITY, f64::min);
    for case in &cases {
        let reference = exact_reference(case, duration, false)?;
        // A third of the finest step of the study, so that even its error is measurable.
        let converged = converged_dda(case, duration, finest / 3.0, false)?;
        for &integ in &integrators {
            for &dt in &dts {
                bump(
                    &mut rows,
                    two_block_row(
                        "timestep",
                        case,
                        duration,
                        integ,
                        dt,
                        None,
                        None,
                        false,
                        &reference,
                        Some(&converged),
                    )?,
                );
            }
        }
    }
    // 2. Fixed base (closed form): pure structural accuracy, no contact events.
    let resonant = &CASES[0];
    let fixed_ref = exact_reference(resonant, duration, true)?;
    let fixed_dts: Vec<f64> = dts.iter().copied().take(4).collect();
    let fixed_finest = fixed_dts.iter().copied().fold(f64::INFINITY, f64::min);
    let fixed_converged = converged_dda(resonant, duration, fixed_finest / 3.0, true)?;
    for &integ in &integrators {
        for &dt in &fixed_dts {
            bump(
                &mut rows,
                two_block_row(
                    "fixed-base",
                    resonant,
                    duration,
                    integ,
                    dt,
                    None,
                    None,
                    true,
                    &fixed_ref,
                    Some(&fixed_converged),
                )?,
            );
        }
    }
    // 3. Penalty stiffness (penalty contacts, Δt = 1 ms, the two-block scene's integrator).
    let scene_default = two_block_integrator()?;
    let reference = exact_reference(resonant, duration, false)?;
    for &p in &penalties {
        bump(
            &mut rows,
            two_block_row(
                "penalty",
                resonant,
                duration,
                scene_default,
                1e-3,
                Some(p),
                None,
                false,
                &reference,
                None,
            )?,
        );
    }
    // 4. Ground model: the paper's large mass against prescribed motion.
    bump(
        &mut rows,
        two_block_row(
            "ground",
            resonant,
            duration,
            scene_default,
            1e-3,
            None,
            None,
            false,
            &reference,
            None,
        )?,
    );
    for &r in &ratios {
        bump(
            &mut rows,
            two_block_row(
                "ground",
                resonant,
                duration,
                scene_default,
                1e-3,
                None,
                Some((GroundKind::LargeMass, r)),
                false,
                &reference,
                None,
            )?,
        );
    }
    // 5. Three-storey El Centro: peak roof acceleration (sliding and fixed) against a
    //    Δt-converged DDA run and against the MDOF model.
    let frame_dts: Vec<f64> = if quick {
        vec![]
    } else {
        vec![1e-2, 3e-3, 1e-3, 3e-4]
    };
    if !frame_dts.is_empty() {
        for fixed_base in [false, true] {
            let base = RunSpec {
                fixed_base,
                duration: Some(15.0),
                ..RunSpec::scene("three-storey")
            };
            let converged = run_frame(&RunSpec {
                dt: Some(1e-4),
                ..base.clone()
            })?
            .summary;
            let mdof = run_mdof(&base)?.summary;
            for integ in [Integrator::Classic, Integrator::default()] {
                for &dt in &frame_dts {
                    let r = run_frame(&RunSpec {
                        dt: Some(dt),
                        integrator: Some(integ),
                        ..base.clone()
                    })?
                    .summary;
                    bump(
                        &mut rows,
                        AccuracyRow {
                            study: "three-storey".into(),
                            case: format!(
                                "{} base, El Centro 15 s (converged roof {:.4} g, MDOF {:.4} g)",
                                if fixed_base { "fixed" } else { "sliding" },
                                converged.peak_roof_accel_g,
                                mdof.peak_roof_accel_g
                            ),
                            integrator: integ.label(),
                            dt,
                            penalty: 2e12,
                            ground: "prescribed".into(),
                            wall_time_s: r.wall_time_s,
                            steps: r.steps,
                            // Signed: whether the scheme's damping lowers the peak.
                            peak_error: (r.peak_roof_accel_g - converged.peak_roof_accel_g)
                                / converged.peak_roof_accel_g,
                            rms_slip: rel(r.max_slip_m.max(1e-9), converged.max_slip_m.max(1e-9)),
                            rms_drift: rel(r.peak_roof_drift_m, converged.peak_roof_drift_m),
                            rms_slip_self: f64::NAN,
                            abase_error: rel(r.peak_roof_accel_g, mdof.peak_roof_accel_g),
                        },
                    );
                }
            }
        }
    }
    Ok(rows)
}

/// Observed order of convergence: the slope of log(error) against log(Δt) over the step
/// sizes where the error is above `floor` (a least-squares fit).
pub fn observed_order(points: &[(f64, f64)], floor: f64) -> Option<f64> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .filter(|(dt, e)| *e > floor && e.is_finite() && *dt > 0.0)
        .map(|(dt, e)| (dt.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Writes `work_precision.csv`, the figures and `report.md`.
pub fn write_accuracy(rows: &[AccuracyRow], out: &Path) -> Result<Vec<PathBuf>> {
    let mut staged = Staged::new(out)?;
    staged.write_csv("work_precision.csv", rows)?;
    let labels: Vec<String> = {
        let mut v: Vec<String> = rows.iter().map(|r| r.integrator.clone()).collect();
        v.sort();
        v.dedup();
        v
    };
    // Work-precision: peak error and RMS slip error against wall time, per integrator.
    let mut fig = Figure::new(
        "Work-precision: two-block cases (DDA against the exact solution)",
        1,
        2,
    );
    for (pi, (title, f)) in [
        (
            "largest peak-metric error",
            (|r: &AccuracyRow| r.peak_error) as fn(&AccuracyRow) -> f64,
        ),
        ("RMS slip error / D", |r: &AccuracyRow| r.rms_slip),
    ]
    .into_iter()
    .enumerate()
    {
        let p = &mut fig.panels[pi];
        p.title = title.into();
        p.x_label = "wall time per run (s)".into();
        p.y_label = "error".into();
        p.x_log = true;
        p.y_log = true;
        for (k, label) in labels.iter().enumerate() {
            let pts: Vec<&AccuracyRow> = rows
                .iter()
                .filter(|r| r.study == "timestep" && &r.integrator == label)
                .collect();
            p.series.push(Series::markers(
                label.clone(),
                pts.iter().map(|r| r.wall_time_s).collect(),
                pts.iter().map(|r| f(r)).collect(),
                k,
            ));
        }
    }
    fig.save_png(&staged.path("work_precision.png"), 1400, 600)?;
    // Convergence: error against Δt, fixed base (smooth) and sliding (resonant case).
    let mut fig = Figure::new("Convergence with Δt", 1, 2);
    for (pi, (study, case_filter, title)) in [
        (
            "fixed-base",
            None,
            "fixed base: max peak error against the SDOF closed form",
        ),
        (
            "timestep",
            Some(CASES[0].name),
            "sliding (resonant case): RMS slip error / D",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let p = &mut fig.panels[pi];
        p.title = title.into();
        p.x_label = "Δt (s)".into();
        p.y_label = "error".into();
        p.x_log = true;
        p.y_log = true;
        for (k, label) in labels.iter().enumerate() {
            let mut pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| {
                    r.study == study
                        && &r.integrator == label
                        && case_filter.is_none_or(|c| r.case == c)
                })
                .map(|r| {
                    (
                        r.dt,
                        if study == "fixed-base" {
                            r.peak_error
                        } else {
                            r.rms_slip
                        },
                    )
                })
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            p.series.push(Series::line(
                label.clone(),
                pts.iter().map(|x| x.0).collect(),
                pts.iter().map(|x| x.1).collect(),
                k,
            ));
        }
    }
    fig.save_png(&staged.path("convergence.png"), 1400, 600)?;
    staged.write("report.md", report_markdown(rows))?;
    staged.commit()
}

fn report_markdown(rows: &[AccuracyRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Error against run time\n");
    let _ = writeln!(
        s,
        "All errors relative (peak metrics: |DDA − exact| / max(|exact|, 0.01) in the paper's \
         normalisation; RMS errors of time histories / D). Wall times are for one run on one \
         core. Generated by `slidebase accuracy`.\n"
    );
    let mut labels: Vec<String> = rows.iter().map(|r| r.integrator.clone()).collect();
    labels.sort();
    labels.dedup();
    let _ = writeln!(s, "## Findings\n");
    for line in findings(rows, &labels) {
        let _ = writeln!(s, "- {line}");
    }
    let _ = writeln!(
        s,
        "\n## Observed order of convergence (least squares of log error against log Δt)\n"
    );
    let _ = writeln!(
        s,
        "Errors against the Δt-converged DDA run of the same case (self-convergence, so \
         that the model's own difference from the exact solution does not mask the order), \
         fitted over the three finest steps (the asymptotic range). Smooth phases: the fixed \
         base, RMS roof-drift error. Sliding: RMS slip error, the resonant case and the \
         median over all cases.\n"
    );
    let _ = writeln!(
        s,
        "| integrator | smooth (fixed base) | sliding, resonant case | sliding, all cases (median) |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|");
    for label in &labels {
        let (smooth, resonant, median) = orders(rows, label);
        let f = |o: Option<f64>| o.map_or("–".into(), |v| format!("{v:.2}"));
        let _ = writeln!(
            s,
            "| {label} | {} | {} | {} |",
            f(smooth),
            f(resonant),
            f(median)
        );
    }
    let _ = writeln!(
        s,
        "\n## Cheapest setting that reaches 1 % on the paper's metrics (two-block cases)\n"
    );
    let _ = writeln!(
        s,
        "| integrator | largest grid-validated Δt (≤ 1 ms) with every case ≤ 1 % | largest peak error there | mean wall time per run there |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|");
    for label in &labels {
        match cheapest_one_percent(rows, label) {
            Some(r) => {
                let _ = writeln!(
                    s,
                    "| {label} | {:e} s | {:.3} % | {:.3} s |",
                    r.dt,
                    100.0 * r.worst,
                    r.wall
                );
            }
            None => {
                let _ = writeln!(s, "| {label} | not reached | – | – |");
            }
        }
    }
    for (study, title, cols) in [
        (
            "penalty",
            "Penalty stiffness (penalty contacts, resonant case, Δt = 1 ms, generalised-α)",
            "normal penalty, N/m (× the blocks' E)",
        ),
        (
            "ground",
            "Ground model (resonant case, Δt = 1 ms)",
            "ground",
        ),
    ] {
        let _ = writeln!(s, "\n## {title}\n");
        let _ = writeln!(
            s,
            "| {cols} | largest peak error | RMS slip / D | RMS drift / D | base accel. error | wall (s) |"
        );
        let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|");
        for r in rows.iter().filter(|r| r.study == study) {
            let key = if study == "penalty" {
                format!("{:.0e} ({:.0e} × E)", r.penalty, r.penalty / BLOCK_E)
            } else {
                r.ground.clone()
            };
            let _ = writeln!(
                s,
                "| {key} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.3} |",
                r.peak_error, r.rms_slip, r.rms_drift, r.abase_error, r.wall_time_s
            );
        }
    }
    let frame: Vec<&AccuracyRow> = rows.iter().filter(|r| r.study == "three-storey").collect();
    if !frame.is_empty() {
        let _ = writeln!(
            s,
            "\n## Three-storey frame, El Centro (15 s): peak roof acceleration against a Δt = 0.1 ms run\n"
        );
        let _ = writeln!(
            s,
            "| case | integrator | Δt (s) | roof accel. error vs converged | vs MDOF | max slip error | wall (s) |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|");
        for r in frame {
            let _ = writeln!(
                s,
                "| {} | {} | {:e} | {:+.2} % | {:.2} % | {:.2} % | {:.2} |",
                r.case,
                r.integrator,
                r.dt,
                100.0 * r.peak_error,
                100.0 * r.abase_error,
                100.0 * r.rms_slip,
                r.wall_time_s
            );
        }
    }
    let _ = writeln!(s, "\n## Every run\n\nSee `work_precision.csv`.");
    s
}

/// Orders of one integrator: smooth (fixed base vs closed form), sliding resonant and the
/// median over the sliding cases (self-convergence).
fn orders(rows: &[AccuracyRow], label: &str) -> (Option<f64>, Option<f64>, Option<f64>) {
    // The three finest steps whose error is above round-off: the asymptotic range.
    let asymptotic = |mut pts: Vec<(f64, f64)>| -> Option<f64> {
        pts.retain(|&(_, e)| e > 1e-9 && e.is_finite());
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        pts.truncate(3);
        observed_order(&pts, 1e-9)
    };
    let smooth = asymptotic(
        rows.iter()
            .filter(|r| r.study == "fixed-base" && r.integrator == label)
            .map(|r| (r.dt, r.rms_slip_self))
            .collect(),
    );
    let case_order = |name: &str| {
        asymptotic(
            rows.iter()
                .filter(|r| r.study == "timestep" && r.integrator == label && r.case == name)
                .map(|r| (r.dt, r.rms_slip_self))
                .collect(),
        )
    };
    let resonant = case_order(CASES[0].name);
    let mut all: Vec<f64> = CASES.iter().filter_map(|c| case_order(c.name)).collect();
    all.sort_by(f64::total_cmp);
    (smooth, resonant, all.get(all.len() / 2).copied())
}

/// The largest Δt at which every two-block case is within 1 % on the paper's metrics, and
/// the mean wall time per run there.
fn cheapest_one_percent(rows: &[AccuracyRow], label: &str) -> Option<Reached> {
    let mut dts: Vec<f64> = rows
        .iter()
        .filter(|r| r.study == "timestep" && r.integrator == label)
        .map(|r| r.dt)
        .filter(|&dt| dt <= LARGEST_GRID_VALIDATED_DT * (1.0 + 1e-9))
        .collect();
    dts.sort_by(|a, b| b.total_cmp(a));
    dts.dedup();
    let at = |dt: f64| {
        rows.iter()
            .filter(move |r| r.study == "timestep" && r.integrator == label && r.dt == dt)
    };
    let dt = dts
        .into_iter()
        .find(|&dt| at(dt).all(|r| r.peak_error <= 0.01))?;
    let sel: Vec<&AccuracyRow> = at(dt).collect();
    let wall = sel.iter().map(|r| r.wall_time_s).sum::<f64>() / sel.len().max(1) as f64;
    let worst = sel.iter().map(|r| r.peak_error).fold(0.0, f64::max);
    Some(Reached { dt, wall, worst })
}

/// Where a scheme first keeps every case within 1 %: the step, the mean wall time per
/// run there, and the largest peak error there.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Reached {
    dt: f64,
    wall: f64,
    worst: f64,
}

/// The largest Δt validated over the whole paper grid (docs/validation.md). The study's
/// few cases cannot show that a coarser step is safe: trapezoidal at 1e-2 passes them
/// and misses a_base by up to 5× elsewhere on the grid, so no coarser step is
/// recommended.
const LARGEST_GRID_VALIDATED_DT: f64 = 1e-3;

/// The report's conclusions, computed from the rows.
fn findings(rows: &[AccuracyRow], labels: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    let order_text: Vec<String> = labels
        .iter()
        .map(|l| {
            let (smooth, _, median) = orders(rows, l);
            let f = |o: Option<f64>| o.map_or("–".into(), |v| format!("{v:.1}"));
            format!("{l} {} (sliding {})", f(smooth), f(median))
        })
        .collect();
    out.push(format!(
        "Observed orders in smooth phases: {}. The classic DDA scheme is first order, the \
         trapezoidal rule and the α-schemes second order; with stick-slip events the \
         sliding runs converge more slowly (the events are located to O(Δt²) but the \
         transitions are not smooth).",
        order_text.join(", ")
    ));
    // The error floor of the model: converged DDA against the exact solution.
    let finest = rows
        .iter()
        .filter(|r| r.study == "timestep")
        .map(|r| r.dt)
        .fold(f64::INFINITY, f64::min);
    let floor: Vec<&AccuracyRow> = rows
        .iter()
        .filter(|r| r.study == "timestep" && r.dt == finest)
        .collect();
    if !floor.is_empty() {
        let worst = floor.iter().map(|r| r.peak_error).fold(0.0, f64::max);
        let worst_base = floor.iter().map(|r| r.abase_error).fold(0.0, f64::max);
        let worst_slip = floor.iter().map(|r| r.rms_slip).fold(0.0, f64::max);
        out.push(format!(
            "Error floor: at Δt = {finest:e} s every scheme has converged to the DDA model's \
             own solution, which differs from the exact mass-spring model by up to {:.2} % on \
             the peak metrics (base acceleration {:.2} %) and {worst_slip:.1e} D in RMS slip. \
             With the stuck joint an exact constraint (the default contacts) the DDA model \
             converges to the exact one; with penalty springs it converged to their ringing \
             at every re-stick instead (+30 % on the base acceleration, issue 13).",
            100.0 * worst,
            100.0 * worst_base
        ));
    }
    let penalty: Vec<&AccuracyRow> = rows.iter().filter(|r| r.study == "penalty").collect();
    if let (Some(soft), Some(stiff)) = (
        penalty
            .iter()
            .min_by(|a, b| a.penalty.total_cmp(&b.penalty)),
        penalty
            .iter()
            .max_by(|a, b| a.penalty.total_cmp(&b.penalty)),
    ) {
        let enough = penalty
            .iter()
            .filter(|r| r.peak_error <= 1.1 * stiff.peak_error)
            .map(|r| r.penalty)
            .fold(f64::INFINITY, f64::min);
        out.push(format!(
            "Penalty stiffness: a soft joint ({:.0e} N/m) costs {:.1} % on the peak metrics; \
             from {enough:.0e} N/m ({:.0e} × E) on the error stays at the time-step floor \
             ({:.2} %) up to {:.0e} N/m ({:.0e} × E), so a stiffer penalty costs no accuracy \
             (the solver stays well conditioned) and the joint's elasticity sets no error \
             above it.",
            soft.penalty,
            100.0 * soft.peak_error,
            enough / BLOCK_E,
            100.0 * stiff.peak_error,
            stiff.penalty,
            stiff.penalty / BLOCK_E
        ));
    }
    let ground: Vec<&AccuracyRow> = rows
        .iter()
        .filter(|r| r.study == "ground" && r.ground.starts_with("large-mass"))
        .collect();
    if !ground.is_empty() {
        let list: Vec<String> = ground
            .iter()
            .map(|r| {
                format!(
                    "{} {:.2} %",
                    r.ground.trim_start_matches("large-mass:"),
                    100.0 * r.peak_error
                )
            })
            .collect();
        let prescribed = rows
            .iter()
            .find(|r| r.study == "ground" && r.ground == "prescribed");
        let slips: Vec<String> = ground
            .iter()
            .map(|r| {
                format!(
                    "{} {:.1e} D",
                    r.ground.trim_start_matches("large-mass:"),
                    r.rms_slip
                )
            })
            .collect();
        out.push(format!(
            "Large-mass ground (paper eq. 4), peak error by m_g/m_structure: {}; prescribed \
             motion {:.2} %. The slip history is more sensitive — RMS slip error {} against \
             {:.1e} D with prescribed motion. A light ground is pushed back by the structure \
             (error ∝ 1/ratio); a very heavy one loses the structure's motion to round-off \
             (its increments are the ground's ± the relative motion, ∝ ratio·ε), so the \
             paper's method has a best ratio (about 1e4, the default mass ratio) and \
             prescribed motion, exact and the default ground, is better than any.",
            list.join(", "),
            100.0 * prescribed.map_or(f64::NAN, |r| r.peak_error),
            slips.join(", "),
            prescribed.map_or(f64::NAN, |r| r.rms_slip)
        ));
    }
    // The largest step wins (the cost is the number of steps); among the schemes that
    // reach it, the most accurate (their wall times differ by noise only).
    let cheapest = labels
        .iter()
        .filter_map(|l| cheapest_one_percent(rows, l).map(|r| (l, r)))
        .min_by(|a, b| {
            b.1.dt
                .total_cmp(&a.1.dt)
                .then(a.1.worst.total_cmp(&b.1.worst))
        });
    match cheapest {
        Some((label, Reached { dt, wall, worst })) => {
            let default = two_block_integrator().map_or(String::new(), |i| i.label());
            let note = if *label == default && (dt - 1e-3).abs() < 1e-12 {
                "— the two-block scene's default".to_string()
            } else {
                format!(
                    "(the two-block scene's default, {default} at Δt = 1 ms, is within 1 % \
                     over the whole paper grid as well (docs/validation.md), and damps what \
                     Δt does not resolve, which the trapezoidal rule would leave ringing in \
                     a variant of the scene with such modes)"
                )
            };
            out.push(format!(
                "Recommended setting: {label} at Δt = {dt:e} s: the largest step that keeps \
                 every two-block case within 1 % on all four paper metrics among the steps \
                 validated over the whole paper grid (Δt ≤ {LARGEST_GRID_VALIDATED_DT:e} s; a \
                 coarser step that passes these few cases can fail elsewhere on the grid), \
                 and of the schemes that reach it, the most accurate (largest error \
                 {:.3} %, {wall:.3} s per run here) {note}.",
                100.0 * worst
            ));
        }
        None => out.push(
            "No setting of the study validated over the paper grid keeps every two-block \
             case within 1 % on all four metrics."
                .into(),
        ),
    }
    let frame = |fixed: bool, label: &str| {
        rows.iter()
            .filter(|r| {
                r.study == "three-storey"
                    && r.integrator == label
                    && r.case.starts_with(if fixed { "fixed" } else { "sliding" })
            })
            .min_by(|a, b| (a.dt - 1e-3).abs().total_cmp(&(b.dt - 1e-3).abs()))
            .map(|r| r.peak_error)
    };
    if let (Some(sc), Some(fc), Some(sg), Some(fg)) = (
        frame(false, "classic"),
        frame(true, "classic"),
        frame(false, "generalized-alpha:0"),
        frame(true, "generalized-alpha:0"),
    ) {
        out.push(format!(
            "Three-storey frame on El Centro at Δt = 1 ms: against a Δt = 0.1 ms run the peak \
             roof acceleration is off by {:+.1} % (sliding) and {:+.1} % (fixed) with the \
             classic scheme, {:+.1} % and {:+.1} % with generalised-α: the sliding/fixed \
             ratio of peak roof accelerations moves by {:+.1} % (classic) and {:+.1} % \
             (generalised-α) from its converged value. Numerical damping is not where the \
             isolation comes from; the ratio is a property of the model (see the table \
             below for the converged values).",
            100.0 * sc,
            100.0 * fc,
            100.0 * sg,
            100.0 * fg,
            100.0 * ((1.0 + sc) / (1.0 + fc) - 1.0),
            100.0 * ((1.0 + sg) / (1.0 + fg) - 1.0)
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(integrator: &str, dt: f64, peak_error: f64) -> AccuracyRow {
        AccuracyRow {
            study: "timestep".into(),
            case: "c".into(),
            integrator: integrator.into(),
            dt,
            penalty: 1e12,
            ground: "prescribed".into(),
            wall_time_s: dt.recip() * 1e-5,
            steps: 1,
            peak_error,
            rms_slip: 0.0,
            rms_drift: 0.0,
            rms_slip_self: f64::NAN,
            abase_error: 0.0,
        }
    }

    /// Issue 13 item 5: a coarse step that passes the study's few cases is not recommended,
    /// since the cases cannot show it is safe over the grid.
    /// At the same step two schemes cost the same number of steps: the recommendation
    /// is the more accurate one, not the one whose runs happened to be faster.
    #[test]
    fn at_equal_steps_the_more_accurate_scheme_is_recommended() {
        let mut fast = row("generalized-alpha:0", 1e-3, 0.008);
        fast.wall_time_s = 0.01;
        let rows = [fast, row("trapezoidal", 1e-3, 0.002)];
        let labels = ["generalized-alpha:0".into(), "trapezoidal".into()];
        let text = findings(&rows, &labels).join("\n");
        assert!(
            text.contains("setting: trapezoidal at Δt = 1e-3 s"),
            "{text}"
        );
    }

    #[test]
    fn no_step_coarser_than_the_grid_validated_one_is_recommended() {
        let rows = [
            row("trapezoidal", 1e-2, 0.005),
            row("trapezoidal", 1e-3, 0.001),
            row("classic", 1e-2, 0.02),
        ];
        assert_eq!(
            cheapest_one_percent(&rows, "trapezoidal").map(|r| r.dt),
            Some(1e-3)
        );
        assert_eq!(cheapest_one_percent(&rows, "classic"), None);
        let text = findings(&rows, &["trapezoidal".into(), "classic".into()]).join("\n");
        assert!(text.contains("trapezoidal at Δt = 1e-3 s"), "{text}");
    }
}
