//! Newmark's sliding block, solved exactly: a rigid block resting on a ground that shakes
//! horizontally (and, optionally, vertically), held by a friction law.
//!
//! In the ground's frame the block's slip s (block relative to ground, +x) obeys
//!
//! ```text
//! stuck:    s' = 0           while |a_g(t)| ≤ μ_s·N(t)
//! slipping: s'' = −a_g(t) − μ(|s'|)·N(t)·d,   d = sign(s') (constant within a slip phase)
//! ```
//!
//! with N(t) = g + a_v(t) the normal force per unit mass (a_v the vertical ground
//! acceleration, up positive). The solver steps onto every kink of the inputs (record
//! samples), so that within a step a_g and N are smooth; there the classical fourth-order
//! Runge–Kutta step is exact for the constant-coefficient laws (Coulomb, static-kinetic:
//! s'' is then linear in t on a record segment, s a cubic) and converged to rounding for
//! the velocity law, whose steps are also kept short against its rate. The switching
//! times (breakaway, slip stop) are located by bisection to [`BlockOptions::root_tolerance`].
//! This is the reference `--model mass-spring` reports for the `block` scene.

use super::exact::{Phase, PhaseEvent};
use crate::dda::FrictionLaw;
use crate::ground_motion::GroundMotion;
use crate::model::friction::Friction;
use crate::{Error, Result};

/// The sliding block's inputs: its friction law, gravity and the ground motion.
#[derive(Debug, Clone)]
pub struct SlidingBlock<'a> {
    /// Friction law of the interface.
    pub friction: Friction,
    /// Gravity, m/s².
    pub gravity: f64,
    /// Horizontal ground acceleration.
    pub horizontal: &'a GroundMotion,
    /// Vertical ground acceleration (up positive), if the ground also shakes vertically.
    pub vertical: Option<&'a GroundMotion>,
}

impl SlidingBlock<'_> {
    /// About how many steps the solution over `duration` takes (for the run-size check).
    pub fn steps(&self, duration: f64, options: &BlockOptions) -> f64 {
        let samples: f64 = std::iter::once(self.horizontal)
            .chain(self.vertical)
            .map(|m| match m {
                GroundMotion::Record(r) => duration.min(r.duration()) / r.dt,
                GroundMotion::Harmonic(_) => 0.0,
            })
            .sum();
        duration / step_length(self, options) + samples
    }
}

/// Numerical settings. The defaults are far tighter than any comparison needs; a test
/// checks that halving the step changes nothing that matters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockOptions {
    /// Longest step, s (steps also end on every record sample).
    pub max_step: f64,
    /// Steps per period of a harmonic input.
    pub steps_per_period: usize,
    /// Absolute tolerance of the switching times, s.
    pub root_tolerance: f64,
    /// Most steps a run may take (the velocity law's steps shrink with its rate).
    pub max_steps: u64,
}

impl Default for BlockOptions {
    fn default() -> Self {
        Self {
            max_step: 1e-3,
            steps_per_period: 400,
            root_tolerance: 1e-13,
            max_steps: 200_000_000,
        }
    }
}

/// Energies per unit mass in the ground's frame, J/kg.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BlockEnergy {
    /// ∫ −a_g·s' dt: work of the inertial (ground) force on the slipping block.
    pub input_work: f64,
    /// ∫ μ·N·|s'| dt: dissipated by friction.
    pub friction_dissipated: f64,
    /// ½ s'² at the end.
    pub kinetic: f64,
    /// input − dissipated − kinetic: zero up to the integration's rounding.
    pub residual: f64,
}

/// The exact response of the sliding block.
#[derive(Debug, Clone, Default)]
pub struct BlockResult {
    /// Output times, s (empty without an output interval).
    pub time: Vec<f64>,
    /// Slip s at the output times, m.
    pub slip: Vec<f64>,
    /// Slip velocity s' at the output times, m/s.
    pub slip_velocity: Vec<f64>,
    /// Absolute horizontal acceleration of the block at the output times, m/s².
    pub accel: Vec<f64>,
    /// Phase changes (the first is the phase at t = 0).
    pub events: Vec<PhaseEvent>,
    /// max |s| over the continuous solution, m.
    pub max_slip: f64,
    /// s at the end, m.
    pub residual_slip: f64,
    /// max |absolute horizontal acceleration of the block|, m/s².
    pub peak_accel: f64,
    /// Energy balance at the end.
    pub energy: BlockEnergy,
    /// Steps taken.
    pub steps: u64,
}

/// The state integrated while the block slips: s, s', input work, friction work.
type State = [f64; 4];

/// Solves the sliding block from rest over `[0, duration]`, with output every
/// `output_dt` seconds (0: peaks only).
///
/// Errors: a normal force that reaches zero (the vertical motion lifts the block off the
/// ground; the message gives the time), or a run that would exceed
/// [`BlockOptions::max_steps`].
pub fn simulate_block(
    block: &SlidingBlock,
    duration: f64,
    output_dt: f64,
    options: &BlockOptions,
) -> Result<BlockResult> {
    let mut run = BlockRun::new(block, options, output_dt);
    run.solve(duration)?;
    Ok(run.result)
}

/// The marching solution.
struct BlockRun<'a, 'b> {
    block: &'b SlidingBlock<'a>,
    options: BlockOptions,
    /// Step length, s.
    h: f64,
    output_dt: f64,
    next_output: f64,
    t: f64,
    y: State,
    phase: Phase,
    result: BlockResult,
}

impl<'a, 'b> BlockRun<'a, 'b> {
    fn new(block: &'b SlidingBlock<'a>, options: &BlockOptions, output_dt: f64) -> Self {
        Self {
            block,
            options: *options,
            h: step_length(block, options),
            output_dt,
            next_output: 0.0,
            t: 0.0,
            y: [0.0; 4],
            phase: Phase::Stick,
            result: BlockResult::default(),
        }
    }

    fn solve(&mut self, duration: f64) -> Result<()> {
        self.check_normal(0.0)?;
        self.result.events.push(PhaseEvent {
            time: 0.0,
            phase: Phase::Stick,
        });
        if self.breaks_loose(0.0) {
            self.start_slip(0.0);
        }
        self.observe();
        while self.t < duration {
            let t1 = self.step_end(duration);
            self.check_normal(t1)?;
            match self.phase {
                Phase::Stick => self.advance_stuck(t1),
                Phase::Slip { direction } => self.advance_slipping(t1, direction),
            }
            self.result.steps += 1;
            if self.result.steps > self.options.max_steps {
                return Err(Error::invalid(
                    "sliding block",
                    format!(
                        "the exact solution would take more than {} steps (the velocity \
                         law's rate sets the step); lower RATE or the duration",
                        self.options.max_steps
                    ),
                ));
            }
            self.observe();
        }
        let r = &mut self.result;
        r.residual_slip = self.y[0];
        let kinetic = 0.5 * self.y[1] * self.y[1];
        r.energy = BlockEnergy {
            input_work: self.y[2],
            friction_dissipated: self.y[3],
            kinetic,
            residual: self.y[2] - self.y[3] - kinetic,
        };
        Ok(())
    }

    /// The end of the next step: one step on, or the next record sample or output time
    /// or the end, whichever comes first.
    fn step_end(&self, duration: f64) -> f64 {
        let mut t1 = (self.t + self.h).min(duration);
        for motion in std::iter::once(self.block.horizontal).chain(self.block.vertical) {
            if let Some(&b) = motion.breakpoints(self.t, t1).first() {
                t1 = t1.min(b);
            }
        }
        if self.output_dt > 0.0 && self.next_output > self.t {
            t1 = t1.min(self.next_output);
        }
        t1
    }

    /// A stuck block: look for the breakaway within (t, t1].
    fn advance_stuck(&mut self, t1: f64) {
        const SAMPLES: usize = 4;
        let t0 = self.t;
        let mut before = t0;
        for k in 1..=SAMPLES {
            let tk = t0 + (t1 - t0) * k as f64 / SAMPLES as f64;
            if self.breaks_loose(tk) {
                let tol = self.options.root_tolerance;
                let at = bisect(before, tk, tol, |t| self.breaks_loose(t));
                self.observe_accel(at);
                self.t = at;
                self.start_slip(at);
                return;
            }
            self.observe_accel(tk);
            before = tk;
        }
        self.t = t1;
    }

    /// A slipping block: integrate to t1, or to the instant its slip velocity returns to
    /// zero, where it sticks or reverses.
    fn advance_slipping(&mut self, t1: f64, direction: f64) {
        let (t0, y0) = (self.t, self.y);
        let y1 = self.rk4(t0, &y0, t1 - t0, direction);
        let Some(end) = self.slip_stop_bracket(t0, &y0, t1, &y1, direction) else {
            self.t = t1;
            self.y = y1;
            return;
        };
        let moving = |t: f64| self.rk4(t0, &y0, t - t0, direction)[1] * direction > 0.0;
        let stop = bisect(t0, end, self.options.root_tolerance, |t| !moving(t));
        let mut y = self.rk4(t0, &y0, stop - t0, direction);
        y[1] = 0.0;
        let last_accel = self.friction_accel(stop, 0.0);
        self.result.peak_accel = self.result.peak_accel.max(last_accel);
        self.track_slip(y[0]);
        self.t = stop;
        self.y = y;
        if self.breaks_loose(stop) {
            // Still driven past the sticking limit: it slides back the other way.
            self.start_slip(stop);
        } else {
            self.set_phase(stop, Phase::Stick);
        }
    }

    /// The end of an interval (t0, end] in which the slip velocity s'·d has its first
    /// zero, if it has one within the step: the step end when s'·d ≤ 0 there, or the
    /// instant of its least value when that is ≤ 0 (within one step the ground
    /// acceleration is linear, so s'·d has at most one minimum, where s''·d turns from
    /// negative to positive).
    fn slip_stop_bracket(&self, t0: f64, y0: &State, t1: f64, y1: &State, d: f64) -> Option<f64> {
        if y1[1] * d <= 0.0 {
            return Some(t1);
        }
        let speed_rate = |t: f64, y: &State| self.slip_rate(t, y, d)[1] * d;
        if !(speed_rate(t0, y0) < 0.0 && speed_rate(t1, y1) > 0.0) {
            return None;
        }
        let at = |t: f64| self.rk4(t0, y0, t - t0, d);
        let tol = self.options.root_tolerance;
        let least = bisect(t0, t1, tol, |t| speed_rate(t, &at(t)) > 0.0);
        (at(least)[1] * d <= 0.0).then_some(least)
    }

    /// One classical Runge–Kutta step of length `h` from (t, y) in slip direction `d`.
    fn rk4(&self, t: f64, y: &State, h: f64, d: f64) -> State {
        let f = |t: f64, y: &State| self.slip_rate(t, y, d);
        let add = |y: &State, k: &State, c: f64| -> State {
            [
                y[0] + c * k[0],
                y[1] + c * k[1],
                y[2] + c * k[2],
                y[3] + c * k[3],
            ]
        };
        let k1 = f(t, y);
        let k2 = f(t + 0.5 * h, &add(y, &k1, 0.5 * h));
        let k3 = f(t + 0.5 * h, &add(y, &k2, 0.5 * h));
        let k4 = f(t + h, &add(y, &k3, h));
        std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }

    /// d/dt of (s, s', input work, friction work) while slipping in direction `d`.
    fn slip_rate(&self, t: f64, y: &State, d: f64) -> State {
        let a_g = self.block.horizontal.accel(t);
        let friction = self.friction_accel(t, y[1]);
        [
            y[1],
            -a_g - friction * d,
            -a_g * y[1],
            // s'·d is the slip speed while the phase lasts.
            friction * y[1] * d,
        ]
    }

    /// μ(|v|)·N(t): the friction force per unit mass at slip velocity `v`.
    fn friction_accel(&self, t: f64, v: f64) -> f64 {
        self.block.friction.sliding_coefficient(v) * self.normal(t)
    }

    /// N(t) = g + a_v(t): the normal force per unit mass.
    fn normal(&self, t: f64) -> f64 {
        self.block.gravity + self.block.vertical.map_or(0.0, |v| v.accel(t))
    }

    /// Whether a block at rest relative to the ground at `t` is driven past its sticking
    /// limit.
    fn breaks_loose(&self, t: f64) -> bool {
        self.block.horizontal.accel(t).abs()
            > self.block.friction.sticking_coefficient() * self.normal(t)
    }

    /// The block breaks loose at `t`: it slips against the ground's acceleration.
    fn start_slip(&mut self, t: f64) {
        let direction = -self.block.horizontal.accel(t).signum();
        self.set_phase(t, Phase::Slip { direction });
    }

    fn set_phase(&mut self, t: f64, phase: Phase) {
        self.phase = phase;
        self.result.events.push(PhaseEvent { time: t, phase });
    }

    /// The lift-off check: the ground must press on the block.
    fn check_normal(&self, t: f64) -> Result<()> {
        let n = self.normal(t);
        if n > 0.0 {
            return Ok(());
        }
        Err(Error::invalid(
            "--vertical-scale",
            format!(
                "the vertical ground acceleration lifts the block off the ground at \
                 t = {t:.4} s (g + a_v = {n:.3} m/s²); the sliding-block model keeps the \
                 block on the ground: lower the vertical scale"
            ),
        ))
    }

    /// Records peaks (and the output sample when one is due) at the current time.
    fn observe(&mut self) {
        let t = self.t;
        let a = self.absolute_accel(t);
        self.result.peak_accel = self.result.peak_accel.max(a.abs());
        self.track_slip(self.y[0]);
        if self.output_dt > 0.0 && t >= self.next_output - 1e-12 {
            let r = &mut self.result;
            r.time.push(t);
            r.slip.push(self.y[0]);
            r.slip_velocity.push(self.y[1]);
            r.accel.push(a);
            self.next_output += self.output_dt;
        }
    }

    /// The peak acceleration at a time inside a stuck step.
    fn observe_accel(&mut self, t: f64) {
        let a = self.block.horizontal.accel(t).abs();
        self.result.peak_accel = self.result.peak_accel.max(a);
    }

    fn track_slip(&mut self, s: f64) {
        self.result.max_slip = self.result.max_slip.max(s.abs());
    }

    /// The block's absolute horizontal acceleration at `t` in the current phase: the
    /// ground's while stuck, the friction force's while slipping.
    fn absolute_accel(&self, t: f64) -> f64 {
        match self.phase {
            Phase::Stick => self.block.horizontal.accel(t),
            Phase::Slip { direction } => -self.friction_accel(t, self.y[1]) * direction,
        }
    }
}

/// The step length: the options' longest step, shortened for a harmonic input's period
/// and for the velocity law's rate (so that the friction's change with speed, which acts
/// as a damper of rate μ'(0)·N, is resolved).
fn step_length(block: &SlidingBlock, options: &BlockOptions) -> f64 {
    let mut h = options.max_step;
    for motion in std::iter::once(block.horizontal).chain(block.vertical) {
        if let GroundMotion::Harmonic(hm) = motion {
            let period = 2.0 * std::f64::consts::PI / hm.omega;
            h = h.min(period / options.steps_per_period as f64);
        }
    }
    if let Friction::Velocity { slow, fast, rate } = block.friction {
        let peak_normal = block.gravity
            + block
                .vertical
                .map_or(0.0, |v| v.peak_accel(v.duration().unwrap_or(f64::MAX)));
        let stiffness = (fast - slow).abs() * rate * peak_normal;
        if stiffness > 0.0 {
            h = h.min(0.1 / stiffness);
        }
    }
    h
}

/// The first time in (lo, hi] at which `event` holds, given that it does not at `lo` and
/// does at `hi`, to within `tol`.
fn bisect(mut lo: f64, mut hi: f64, tol: f64, event: impl Fn(f64) -> bool) -> f64 {
    while hi - lo > tol {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if event(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ground_motion::Harmonic;

    fn harmonic(amplitude_g: f64, hz: f64) -> GroundMotion {
        GroundMotion::Harmonic(Harmonic::from_g_hz(amplitude_g, hz).unwrap())
    }

    fn solve(friction: Friction, motion: &GroundMotion, duration: f64) -> BlockResult {
        let block = SlidingBlock {
            friction,
            gravity: 9.81,
            horizontal: motion,
            vertical: None,
        };
        simulate_block(&block, duration, 0.0, &BlockOptions::default()).unwrap()
    }

    /// Below the sticking limit the block moves with the ground.
    #[test]
    fn a_weak_shake_never_moves_the_block() {
        let m = harmonic(0.1, 1.0);
        let r = solve(Friction::Coulomb(0.2), &m, 5.0);
        assert_eq!(r.max_slip, 0.0);
        assert!((r.peak_accel - 0.1 * 9.80665).abs() < 1e-3);
    }

    /// Frictionless: the block stays where it was in space, so s = −u_g exactly.
    #[test]
    fn a_frictionless_block_stays_put_in_space() {
        let m = harmonic(0.3, 1.0);
        let r = solve(Friction::Coulomb(0.0), &m, 3.0);
        assert!((r.residual_slip + m.displacement(3.0)).abs() < 1e-9);
        assert!(r.peak_accel < 1e-9);
    }

    /// A constant ground acceleration a > μg from rest: the block slips with
    /// s'' = −(a − μg), so s = −½(a − μg)t², and dissipates μg·|s|.
    #[test]
    fn a_constant_pull_gives_the_closed_form() {
        let record = crate::ground_motion::Record::new("step", 0.01, vec![3.0; 201]).unwrap();
        let m = GroundMotion::Record(std::sync::Arc::new(record));
        let mu = 0.2;
        let r = solve(Friction::Coulomb(mu), &m, 1.5);
        let expected = -0.5 * (3.0 - mu * 9.81) * 1.5 * 1.5;
        assert!((r.residual_slip - expected).abs() < 1e-12 * expected.abs().max(1.0));
        assert!((r.energy.friction_dissipated - mu * 9.81 * expected.abs()).abs() < 1e-9);
        assert!(r.energy.residual.abs() < 1e-12 * r.energy.input_work.abs());
    }

    /// Halving the step changes the slip of every law by rounding only.
    #[test]
    fn the_solution_does_not_depend_on_the_step() {
        let m = harmonic(0.4, 1.5);
        for law in [
            Friction::Coulomb(0.2),
            Friction::StaticKinetic {
                stick: 0.3,
                slide: 0.2,
            },
            Friction::Velocity {
                slow: 0.1,
                fast: 0.25,
                rate: 20.0,
            },
        ] {
            let block = SlidingBlock {
                friction: law,
                gravity: 9.81,
                horizontal: &m,
                vertical: None,
            };
            let coarse = simulate_block(&block, 6.0, 0.0, &BlockOptions::default()).unwrap();
            let fine_options = BlockOptions {
                max_step: 2.5e-4,
                steps_per_period: 1600,
                ..BlockOptions::default()
            };
            let fine = simulate_block(&block, 6.0, 0.0, &fine_options).unwrap();
            assert!(coarse.max_slip > 1e-3, "{law}: the block should slide");
            let d = (coarse.max_slip - fine.max_slip).abs() / fine.max_slip;
            let e = (coarse.residual_slip - fine.residual_slip).abs() / fine.max_slip;
            assert!(d < 1e-8 && e < 1e-8, "{law}: {d:e} {e:e}");
            let balance = coarse.energy.residual / coarse.energy.input_work.abs();
            assert!(balance.abs() < 1e-8, "{law}: energy residual {balance:e}");
        }
    }

    /// A vertical acceleration that exceeds g is a lift-off, reported with its time.
    #[test]
    fn lift_off_is_refused_with_its_time() {
        let h = harmonic(0.3, 1.0);
        let v = harmonic(1.2, 1.0);
        let block = SlidingBlock {
            friction: Friction::Coulomb(0.2),
            gravity: 9.80665,
            horizontal: &h,
            vertical: Some(&v),
        };
        let err = simulate_block(&block, 2.0, 0.0, &BlockOptions::default()).unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("lifts the block off") && text.contains("t = "),
            "{text}"
        );
    }
}
