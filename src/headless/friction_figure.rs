//! The friction hysteresis of a sliding-block run: the friction force the joint carried,
//! per unit normal force, against the slip speed — the μ(v) loop of the velocity law, the
//! jump of the static-kinetic law, Coulomb's rectangle — with the law itself drawn over it.
//!
//! On a flat joint the only horizontal force on the block is the friction, so the block's
//! absolute acceleration is F/m and the normal force is m(g + a_v): the ratio
//! F/N = a/(g + a_v) needs no force output from the solver, and the DDA run and the exact
//! block are measured alike.

use super::block::{BlockOutcome, SlipOverlay};
use super::simulate::ModelRun;
use crate::model::friction::{Friction, FrictionLaw};
use crate::post::history::History;
use crate::post::plot::{Figure, Series};
use crate::setup::RunSetup;

/// The figure, or `None` where it has no meaning (a dish, whose slope also pushes the
/// block, or a run without history).
pub fn friction_figure(
    setup: &RunSetup,
    outcome: &BlockOutcome,
    overlays: &[SlipOverlay],
) -> Option<Figure> {
    if setup.dish_radius().is_some() || outcome.run.history.len() < 3 {
        return None;
    }
    let law = setup.joint_law();
    let vertical = setup
        .vertical
        .as_ref()
        .map_or(String::new(), |v| format!(" + vertical {}", v.label()));
    let mut fig = Figure::new(
        format!(
            "friction against slip speed: {law}, {}{vertical}",
            outcome.summary.record
        ),
        1,
        1,
    );
    let p = &mut fig.panels[0];
    p.title = "friction force / normal force (stick: vertical segments at v = 0)".into();
    p.x_label = "slip speed v (m/s)".into();
    p.y_label = "F / N".into();
    let (v, ratio) = friction_loop(setup, &outcome.run);
    let span = v.iter().fold(0.0_f64, |m, x| m.max(x.abs())).max(1e-3);
    // The law first, so that the runs are drawn over it.
    let (lv, lmu) = law_curve(&law, span);
    p.series
        .push(Series::line("the law, −μ(v)·sgn v", lv, lmu, 6));
    p.series
        .push(Series::line(outcome.summary.model.clone(), v, ratio, 1));
    if let Some(exact) = overlays.iter().find(|o| o.markers) {
        let (v, ratio) = friction_loop(setup, &exact.run);
        let every = (v.len() / 400).max(1);
        let pick = |x: Vec<f64>| x.into_iter().step_by(every).collect::<Vec<_>>();
        p.series.push(Series::markers(
            exact.label.clone(),
            pick(v),
            pick(ratio),
            0,
        ));
    }
    Some(fig)
}

/// The friction loop of a block run on a flat joint: the slip speed (central differences
/// of the slip) and F/N = a/(g + a_v) at each interior sample of its history.
pub fn friction_loop(setup: &RunSetup, run: &ModelRun) -> (Vec<f64>, Vec<f64>) {
    let h: &History = &run.history;
    let column = |name: &str| h.column(name).map(<[f64]>::to_vec).unwrap_or_default();
    let (t, slip, accel) = (
        column("time_s"),
        column("slip_m"),
        column("base_accel_m_s2"),
    );
    let g = setup.scene.gravity;
    let mut v = Vec::with_capacity(t.len());
    let mut ratio = Vec::with_capacity(t.len());
    for k in 1..t.len().saturating_sub(1) {
        let dt = t[k + 1] - t[k - 1];
        if dt <= 0.0 {
            continue;
        }
        let up = setup.vertical.as_ref().map_or(0.0, |m| m.accel(t[k]));
        v.push((slip[k + 1] - slip[k - 1]) / dt);
        ratio.push(accel[k] / (g + up));
    }
    (v, ratio)
}

/// The law's sliding branch −μ(v)·sgn v over ±`span` m/s (and its sticking limits at
/// v = 0 drawn as the vertical jump).
fn law_curve(law: &Friction, span: f64) -> (Vec<f64>, Vec<f64>) {
    let n = 200;
    let mut v = Vec::with_capacity(2 * n + 2);
    let mut mu = Vec::with_capacity(2 * n + 2);
    for k in (1..=n).rev() {
        let x = -span * k as f64 / n as f64;
        v.push(x);
        mu.push(law.sliding_coefficient(x));
    }
    let stick = law.sticking_coefficient();
    if stick.is_finite() {
        v.extend([0.0, 0.0]);
        mu.extend([stick, -stick]);
    }
    for k in 1..=n {
        let x = span * k as f64 / n as f64;
        v.push(x);
        mu.push(-law.sliding_coefficient(x));
    }
    (v, mu)
}
