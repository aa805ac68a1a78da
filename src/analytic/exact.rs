//! Exact event-driven solution of the shear building on a sliding raft.

use std::cell::RefCell;

use nalgebra::{DMatrix, DVector};
use smallvec::SmallVec;

use super::ShearBuilding;
use crate::ground_motion::GroundMotion;
use crate::linalg::Modal;
pub(crate) use crate::linalg::modal;
use crate::{Error, Result};

/// Contact phase of the raft.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phase {
    /// The raft moves with the ground.
    Stick,
    /// The raft slips; `direction` = sign of the slip velocity u̇_s.
    Slip {
        /// +1 or −1.
        direction: f64,
    },
}

/// A phase change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseEvent {
    /// When, s.
    pub time: f64,
    /// The phase that starts.
    pub phase: Phase,
}

/// Numerical settings of the exact solver. The defaults are far tighter than any use
/// needs; a test checks that tightening them further changes nothing that matters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExactOptions {
    /// Propagation steps per shortest period (natural or excitation). 32 keeps ωh ≤ 0.2,
    /// where a 10-point Gauss–Legendre rule integrates the Duhamel integral to rounding.
    pub steps_per_period: usize,
    /// Gauss–Legendre points per step (2 to 16).
    pub quadrature_points: usize,
    /// Sample points per step at which switching and extremum conditions are checked;
    /// 4 gives 128 checks per period, so that no sign change of a smooth function is missed.
    pub samples_per_step: usize,
    /// Absolute tolerance of event and extremum times, s.
    pub root_tolerance: f64,
    /// Phase changes kept in [`ExactResult::events`] (the first ones; later ones still
    /// count in the peaks and energies), so that memory does not grow with the duration.
    pub max_events: usize,
}

impl Default for ExactOptions {
    fn default() -> Self {
        Self {
            steps_per_period: 32,
            quadrature_points: 10,
            samples_per_step: 4,
            root_tolerance: 1e-13,
            max_events: 100_000,
        }
    }
}

/// Peak absolute values over the whole continuous solution.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Peaks {
    /// max |u_s|, m.
    pub slip: f64,
    /// max |u_r| of the top storey relative to the raft, m.
    pub roof_drift: f64,
    /// max |absolute raft acceleration|, m/s².
    pub raft_accel: f64,
    /// max |absolute top-storey acceleration|, m/s².
    pub roof_accel: f64,
    /// max |ground acceleration|, m/s².
    pub ground_accel: f64,
}

/// Energy balance in the ground's absolute frame, J (per unit of the masses' units).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EnergyBalance {
    /// ∫ F·u̇0 dt: work of the friction force the ground exerts on the raft.
    pub input_work: f64,
    /// Absolute kinetic energy at the end.
    pub kinetic: f64,
    /// Storey spring energy at the end.
    pub strain: f64,
    /// ρW Σ|Δu_s| over the slip phases.
    pub friction_dissipated: f64,
    /// input − (kinetic + strain + dissipated): zero up to quadrature rounding.
    pub residual: f64,
    /// The energy that has passed through the model: the largest stored (kinetic +
    /// strain) energy of the run plus the friction dissipated, or |input| if larger.
    /// The residual is relative to it, so a run in which nothing slides (input work ~0,
    /// all of it given back) still has a meaningful relative residual.
    pub scale: f64,
}

impl EnergyBalance {
    /// The residual relative to [`EnergyBalance::scale`] (0 for a model at rest).
    pub fn residual_relative(&self) -> f64 {
        if self.scale > 0.0 {
            self.residual / self.scale
        } else {
            0.0
        }
    }
}

/// The exact response.
#[derive(Debug, Clone, Default)]
pub struct ExactResult {
    /// Output times, s.
    pub time: Vec<f64>,
    /// Slip u_s of the raft relative to the ground, m.
    pub slip: Vec<f64>,
    /// Slip velocity, m/s.
    pub slip_velocity: Vec<f64>,
    /// Absolute raft acceleration, m/s².
    pub raft_accel: Vec<f64>,
    /// Storey displacements relative to the raft, `storey_drift[storey][sample]`, m.
    pub storey_drift: Vec<Vec<f64>>,
    /// Absolute storey accelerations, `storey_accel[storey][sample]`, m/s².
    pub storey_accel: Vec<Vec<f64>>,
    /// Phase changes (the first entry is the phase at t = 0).
    pub events: Vec<PhaseEvent>,
    /// Peaks over the continuous solution.
    pub peaks: Peaks,
    /// Energy balance at the end.
    pub energy: EnergyBalance,
    /// Slip at the end of the run, m.
    pub residual_slip: f64,
    /// Propagation steps taken.
    pub steps: u64,
}

/// Mass and stiffness of the stuck building (unknowns: storey displacements u_r).
pub(crate) fn stick_matrices(b: &ShearBuilding) -> (DMatrix<f64>, DMatrix<f64>) {
    let n = b.storey_masses.len();
    let m = DMatrix::from_diagonal(&DVector::from_vec(b.storey_masses.clone()));
    let mut k = DMatrix::zeros(n, n);
    for i in 0..n {
        k[(i, i)] += b.storey_stiffnesses[i];
        if i + 1 < n {
            let kk = b.storey_stiffnesses[i + 1];
            k[(i, i)] += kk;
            k[(i, i + 1)] -= kk;
            k[(i + 1, i)] -= kk;
        }
    }
    (m, k)
}

/// Values per storey (or per mode) of one state, stored inline up to eight: the
/// propagation is evaluated hundreds of thousands of times per run, and heap vectors for
/// its few numbers cost more than the arithmetic (a third of the run, measured).
type StateVec = SmallVec<[f64; 8]>;

/// One linear phase: M ẍ + K x = b ü0(t) + δ c, in modal form.
struct PhaseSystem {
    modal: Modal,
    /// Modal forcing per unit ground acceleration, Φᵀ b.
    beta: Vec<f64>,
    /// Modal constant forcing for δ = +1, Φᵀ c.
    gamma: Vec<f64>,
    /// Φᵀ M, which maps physical states to modal ones (q = Φᵀ M x); formed once.
    projector: DMatrix<f64>,
}

impl PhaseSystem {
    fn new(m: DMatrix<f64>, k: &DMatrix<f64>, b: &DVector<f64>, c: &DVector<f64>) -> Result<Self> {
        let modal = modal(&m, k)?;
        let beta = (modal.phi.transpose() * b).iter().copied().collect();
        let gamma = (modal.phi.transpose() * c).iter().copied().collect();
        let projector = modal.phi.transpose() * &m;
        Ok(Self {
            modal,
            beta,
            gamma,
            projector,
        })
    }
}

/// `a x` for a small dense matrix, without allocating.
fn times(a: &DMatrix<f64>, x: &[f64]) -> StateVec {
    (0..a.nrows())
        .map(|i| (0..a.ncols()).map(|j| a[(i, j)] * x[j]).sum())
        .collect()
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the Legendre polynomial).
fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (mut p1, mut p2) = (1.0, 0.0);
            for j in 0..n {
                let p3 = p2;
                p2 = p1;
                p1 = ((2 * j + 1) as f64 * z * p2 - j as f64 * p3) / (j + 1) as f64;
            }
            let pp = n as f64 * (z * p1 - p2) / (z * z - 1.0);
            let dz = p1 / pp;
            z -= dz;
            if dz.abs() < 1e-16 {
                let w_i = 2.0 / ((1.0 - z * z) * pp * pp);
                x[i] = z;
                w[i] = w_i;
                break;
            }
        }
    }
    (x, w)
}

/// `(sin(ωx)/ω, cos(ωx))`, with the limits `(x, 1)` for a rigid mode (ω = 0), which
/// needs no trigonometry.
#[inline]
fn sin_cos_over(omega: f64, x: f64) -> (f64, f64) {
    if omega == 0.0 {
        (x, 1.0)
    } else {
        let (sin, cos) = (omega * x).sin_cos();
        (sin / omega, cos)
    }
}

/// Full physical state at one time.
#[derive(Debug, Clone)]
struct Snapshot {
    t: f64,
    phase: Phase,
    u_s: f64,
    v_s: f64,
    u_r: StateVec,
    v_r: StateVec,
    ground_accel: f64,
}

struct Solver<'a> {
    b: &'a ShearBuilding,
    ground: &'a GroundMotion,
    opts: ExactOptions,
    stick: PhaseSystem,
    slip: PhaseSystem,
    quad_x: Vec<f64>,
    quad_w: Vec<f64>,
    weight: f64,
    /// The trigonometry of the step lengths propagated over lately (see [`StepTrig`]).
    trig: RefCell<StepTrigCache>,
}

/// What a propagation over `τ` computes from `τ` alone, in one phase's system: the
/// quadrature nodes on `[0, τ]` and, per mode, `sin ωτ`, `cos ωτ`, `sin(ωτ)/ω` and the
/// Duhamel kernel `(sin ω(τ − s)/ω, cos ω(τ − s))` at each node. Nearly every propagation
/// of a run is over one of a few lengths — the step's sample points and the nodes of its
/// energy quadrature, the same fractions of the same nominal step — so these values,
/// computed once per length, are looked up rather than recomputed: on the two-block model
/// at Ω/ω = 5 they were 2.6 M calls of `sin_cos`, a third of the run. The values are the
/// same computations, so the results are the same to the bit.
struct StepTrig {
    tau_bits: u64,
    slip: bool,
    /// (s, weight) of each quadrature node.
    nodes: SmallVec<[(f64, f64); 16]>,
    /// (sin ωτ, cos ωτ, sin(ωτ)/ω) per mode.
    modes: ModeTrigs,
    /// (sin ω(τ − s)/ω, cos ω(τ − s)), mode-major.
    kernel: Vec<(f64, f64)>,
    /// (sin Ωs, cos Ωs) at each node for a harmonic ground of frequency Ω (empty for a
    /// record): its acceleration at the nodes is then `A (sin Ωt₀ cos Ωs + cos Ωt₀ sin Ωs)`,
    /// one sine per propagation instead of one per node (a third of a harmonic run).
    ground: SmallVec<[(f64, f64); 16]>,
}

/// Per-mode triples, inline up to eight modes.
type ModeTrigs = SmallVec<[(f64, f64, f64); 8]>;

/// The last [`STEP_TRIG_SLOTS`] step lengths' [`StepTrig`], replaced in turn.
#[derive(Default)]
struct StepTrigCache {
    slots: Vec<StepTrig>,
    next: usize,
}

/// Step lengths kept: a step's four samples and ten energy nodes, in both phases, with
/// room for the last step's shorter length.
const STEP_TRIG_SLOTS: usize = 32;

impl StepTrigCache {
    /// The entry for `tau` in `sys`, computed if it is not held.
    fn get(
        &mut self,
        tau: f64,
        slip: bool,
        sys: &PhaseSystem,
        quad: (&[f64], &[f64]),
        ground_omega: Option<f64>,
    ) -> &StepTrig {
        let key = tau.to_bits();
        if let Some(i) = self
            .slots
            .iter()
            .position(|e| e.tau_bits == key && e.slip == slip)
        {
            return &self.slots[i];
        }
        let entry = StepTrig::new(tau, slip, sys, quad, ground_omega);
        let i = if self.slots.len() < STEP_TRIG_SLOTS {
            self.slots.push(entry);
            self.slots.len() - 1
        } else {
            let i = self.next;
            self.slots[i] = entry;
            self.next = (i + 1) % STEP_TRIG_SLOTS;
            i
        };
        &self.slots[i]
    }
}

impl StepTrig {
    fn new(
        tau: f64,
        slip: bool,
        sys: &PhaseSystem,
        (quad_x, quad_w): (&[f64], &[f64]),
        ground_omega: Option<f64>,
    ) -> Self {
        let nodes: SmallVec<[(f64, f64); 16]> = quad_x
            .iter()
            .zip(quad_w)
            .map(|(&x, &w)| (0.5 * tau * (1.0 + x), 0.5 * tau * w))
            .collect();
        let omega = &sys.modal.omega;
        let modes = omega
            .iter()
            .map(|&w| {
                let (sn, cs) = (w * tau).sin_cos();
                (sn, cs, sin_cos_over(w, tau).0)
            })
            .collect();
        let kernel = omega
            .iter()
            .flat_map(|&w| nodes.iter().map(move |&(s, _)| sin_cos_over(w, tau - s)))
            .collect();
        let ground = match ground_omega {
            Some(big_omega) => nodes
                .iter()
                .map(|&(s, _)| (big_omega * s).sin_cos())
                .collect(),
            None => SmallVec::new(),
        };
        Self {
            tau_bits: tau.to_bits(),
            slip,
            nodes,
            modes,
            kernel,
            ground,
        }
    }
}

impl Solver<'_> {
    fn system(&self, phase: Phase) -> (&PhaseSystem, f64) {
        match phase {
            Phase::Stick => (&self.stick, 0.0),
            Phase::Slip { direction } => (&self.slip, direction),
        }
    }

    /// Modal coordinates of a snapshot in its phase's system.
    fn to_modal(&self, s: &Snapshot) -> (StateVec, StateVec) {
        let (sys, _) = self.system(s.phase);
        match s.phase {
            Phase::Stick => (times(&sys.projector, &s.u_r), times(&sys.projector, &s.v_r)),
            Phase::Slip { .. } => {
                let x: StateVec = std::iter::once(s.u_s)
                    .chain(s.u_r.iter().copied())
                    .collect();
                let v: StateVec = std::iter::once(s.v_s)
                    .chain(s.v_r.iter().copied())
                    .collect();
                (times(&sys.projector, &x), times(&sys.projector, &v))
            }
        }
    }

    /// Exact state at `t0 + tau` from modal state (q0, qd0) at `t0` in `phase`.
    fn propagate(&self, start: &Snapshot, q0: &[f64], qd0: &[f64], tau: f64) -> Snapshot {
        let (sys, delta) = self.system(start.phase);
        let t0 = start.t;
        let n = q0.len();
        let mut cache = self.trig.borrow_mut();
        let slip = matches!(start.phase, Phase::Slip { .. });
        let harmonic = match self.ground {
            GroundMotion::Harmonic(h) => Some(*h),
            GroundMotion::Record(_) => None,
        };
        let quad = (self.quad_x.as_slice(), self.quad_w.as_slice());
        let trig = cache.get(tau, slip, sys, quad, harmonic.map(|h| h.omega));
        // Ground acceleration at the quadrature nodes on [0, τ] (at most 16 nodes).
        let mut accel_store = [0.0; 16];
        match harmonic {
            Some(h) => {
                let (sin0, cos0) = (h.omega * t0).sin_cos();
                for (a, &(sn, cs)) in accel_store.iter_mut().zip(&trig.ground) {
                    *a = h.amplitude * (sin0 * cs + cos0 * sn);
                }
            }
            None => {
                for (a, &(s, _)) in accel_store.iter_mut().zip(&trig.nodes) {
                    *a = self.ground.accel(t0 + s);
                }
            }
        }
        let accel = &accel_store[..trig.nodes.len()];
        let mut q = StateVec::from_elem(0.0, n);
        let mut qd = StateVec::from_elem(0.0, n);
        let kernels = trig.kernel.chunks_exact(trig.nodes.len());
        for (j, (&(sn, cs, sin_over_w), kernel)) in trig.modes.iter().zip(kernels).enumerate() {
            let w = sys.modal.omega[j];
            let mut conv = 0.0;
            let mut conv_d = 0.0;
            for ((&(_, wt), &a), &(k_sin, k_cos)) in trig.nodes.iter().zip(accel).zip(kernel) {
                let f = sys.beta[j] * a + delta * sys.gamma[j];
                conv += wt * k_sin * f;
                conv_d += wt * k_cos * f;
            }
            q[j] = q0[j] * cs + qd0[j] * sin_over_w + conv;
            qd[j] = -q0[j] * w * sn + qd0[j] * cs + conv_d;
        }
        drop(cache);
        let x = times(&sys.modal.phi, &q);
        let v = times(&sys.modal.phi, &qd);
        let t = t0 + tau;
        let ground_accel = self.ground.accel(t);
        match start.phase {
            Phase::Stick => Snapshot {
                t,
                phase: start.phase,
                u_s: start.u_s,
                v_s: 0.0,
                u_r: x,
                v_r: v,
                ground_accel,
            },
            Phase::Slip { .. } => Snapshot {
                t,
                phase: start.phase,
                u_s: x[0],
                v_s: v[0],
                u_r: x[1..].iter().copied().collect(),
                v_r: v[1..].iter().copied().collect(),
                ground_accel,
            },
        }
    }

    /// Friction force the ground must exert on the raft to keep it stuck, N.
    fn holding_force(&self, s: &Snapshot) -> f64 {
        self.b.raft_mass * s.ground_accel - self.b.storey_stiffnesses[0] * s.u_r[0]
    }

    /// Friction force the ground exerts on the raft in the snapshot's phase, N.
    fn friction_force(&self, s: &Snapshot) -> f64 {
        match s.phase {
            Phase::Stick => self.holding_force(s),
            Phase::Slip { direction } => -direction * self.b.friction * self.weight,
        }
    }

    /// Absolute raft acceleration and its rate.
    fn raft_accel(&self, s: &Snapshot) -> (f64, f64) {
        match s.phase {
            Phase::Stick => (s.ground_accel, self.ground.accel_rate(s.t)),
            Phase::Slip { .. } => {
                let k1 = self.b.storey_stiffnesses[0];
                (
                    (self.friction_force(s) + k1 * s.u_r[0]) / self.b.raft_mass,
                    k1 * s.v_r[0] / self.b.raft_mass,
                )
            }
        }
    }

    /// Absolute acceleration of storey i (0-based) and its rate, from the spring forces.
    fn storey_accel(&self, s: &Snapshot, i: usize) -> (f64, f64) {
        let k = &self.b.storey_stiffnesses;
        let n = k.len();
        let below = |u: &[f64]| if i == 0 { u[0] } else { u[i] - u[i - 1] };
        let above = |u: &[f64]| if i + 1 < n { u[i + 1] - u[i] } else { 0.0 };
        let ka = if i + 1 < n { k[i + 1] } else { 0.0 };
        let m = self.b.storey_masses[i];
        (
            (-k[i] * below(&s.u_r) + ka * above(&s.u_r)) / m,
            (-k[i] * below(&s.v_r) + ka * above(&s.v_r)) / m,
        )
    }

    /// Switching function of the phase: crosses from ≤ 0 to > 0 when the phase ends.
    fn switching(&self, s: &Snapshot) -> f64 {
        match s.phase {
            Phase::Stick => {
                if self.b.friction.is_infinite() {
                    -1.0
                } else {
                    self.holding_force(s).abs() - self.b.friction * self.weight
                }
            }
            Phase::Slip { direction } => -direction * s.v_s,
        }
    }

    /// Finds τ in (a, b] where f crosses from ≤ 0 to > 0 (Illinois regula falsi with
    /// bisection safeguard).
    fn root(
        &self,
        mut a: f64,
        mut fa: f64,
        mut b: f64,
        mut fb: f64,
        f: &dyn Fn(f64) -> f64,
    ) -> f64 {
        if fa == 0.0 {
            return a;
        }
        let mut side = 0;
        for _ in 0..200 {
            if (b - a).abs() <= self.opts.root_tolerance {
                break;
            }
            let mut c = (a * fb - b * fa) / (fb - fa);
            if !(c > a.min(b) && c < a.max(b)) {
                c = 0.5 * (a + b);
            }
            let fc = f(c);
            if fc == 0.0 {
                return c;
            }
            if (fc > 0.0) == (fb > 0.0) {
                b = c;
                fb = fc;
                if side == -1 {
                    fa *= 0.5;
                }
                side = -1;
            } else {
                a = c;
                fa = fc;
                if side == 1 {
                    fb *= 0.5;
                }
                side = 1;
            }
        }
        0.5 * (a + b)
    }
}

/// Peak trackers over the continuous solution.
struct PeakSet {
    peaks: Peaks,
}

/// Simulates the building from rest under `ground` for `duration` seconds, recording the
/// state every `output_dt` seconds (≤ 0: no histories, only peaks and energies).
pub fn simulate(
    b: &ShearBuilding,
    ground: &GroundMotion,
    duration: f64,
    output_dt: f64,
    opts: &ExactOptions,
) -> Result<ExactResult> {
    b.validate()?;
    crate::error::require_positive("duration", duration)?;
    if !(2..=16).contains(&opts.quadrature_points)
        || opts.steps_per_period < 4
        || opts.samples_per_step < 1
    {
        return Err(Error::invalid(
            "exact solver options",
            "quadrature_points in 2..=16, steps_per_period >= 4",
        ));
    }
    let n = b.storey_masses.len();
    let weight = b.weight();
    let m_tot: f64 = b.raft_mass + b.storey_masses.iter().sum::<f64>();
    // Stick: unknowns u_r.
    let (ms, ks) = stick_matrices(b);
    let bs = DVector::from_iterator(n, b.storey_masses.iter().map(|m| -m));
    let stick = PhaseSystem::new(ms, &ks, &bs, &DVector::zeros(n))?;
    // Slip: unknowns (u_s, u_r); total-momentum form keeps M symmetric.
    let mut mslip = DMatrix::zeros(n + 1, n + 1);
    mslip[(0, 0)] = m_tot;
    for i in 0..n {
        mslip[(0, i + 1)] = b.storey_masses[i];
        mslip[(i + 1, 0)] = b.storey_masses[i];
        mslip[(i + 1, i + 1)] = b.storey_masses[i];
    }
    let mut kslip = DMatrix::zeros(n + 1, n + 1);
    kslip.view_mut((1, 1), (n, n)).copy_from(&ks);
    let mut bslip = DVector::zeros(n + 1);
    bslip[0] = -m_tot;
    for i in 0..n {
        bslip[i + 1] = -b.storey_masses[i];
    }
    let mut cslip = DVector::zeros(n + 1);
    cslip[0] = -if b.friction.is_finite() {
        b.friction
    } else {
        0.0
    } * weight;
    let slip = PhaseSystem::new(mslip, &kslip, &bslip, &cslip)?;
    let (quad_x, quad_w) = gauss_legendre(opts.quadrature_points);
    let solver = Solver {
        b,
        ground,
        opts: *opts,
        stick,
        slip,
        quad_x,
        quad_w,
        weight,
        trig: RefCell::default(),
    };

    // Step size: a fraction of the shortest period, natural (either phase) or excitation.
    let mut w_max = solver
        .stick
        .modal
        .omega
        .iter()
        .chain(&solver.slip.modal.omega)
        .fold(0.0_f64, |a, &w| a.max(w));
    if let GroundMotion::Harmonic(h) = ground {
        w_max = w_max.max(h.omega);
    }
    let h_nominal = 2.0 * std::f64::consts::PI / w_max / opts.steps_per_period as f64;

    let mut state = Snapshot {
        t: 0.0,
        phase: Phase::Stick,
        u_s: 0.0,
        v_s: 0.0,
        u_r: StateVec::from_elem(0.0, n),
        v_r: StateVec::from_elem(0.0, n),
        ground_accel: ground.accel(0.0),
    };
    if solver.switching(&state) > 0.0 {
        state.phase = Phase::Slip {
            direction: -solver.holding_force(&state).signum(),
        };
    }
    let mut result = ExactResult {
        storey_drift: vec![Vec::new(); n],
        storey_accel: vec![Vec::new(); n],
        events: vec![PhaseEvent {
            time: 0.0,
            phase: state.phase,
        }],
        ..ExactResult::default()
    };
    let mut peaks = PeakSet {
        peaks: Peaks::default(),
    };
    peaks.peaks.ground_accel = ground.peak_accel(duration);
    let mut energy = EnergyBalance::default();
    let mut most_stored = 0.0_f64;
    let mut next_output = 0.0;
    let mut output_index = 0u64;
    let record_output = |res: &mut ExactResult, s: &Snapshot| {
        res.time.push(s.t);
        res.slip.push(s.u_s);
        res.slip_velocity.push(s.v_s);
        res.raft_accel.push(solver.raft_accel(s).0);
        for i in 0..n {
            res.storey_drift[i].push(s.u_r[i]);
            res.storey_accel[i].push(solver.storey_accel(s, i).0);
        }
    };
    if output_dt > 0.0 {
        record_output(&mut result, &state);
        output_index = 1;
        next_output = output_dt;
    }
    offer_peaks(&solver, &mut peaks, &state);
    let mut zero_length_events = 0;
    let end_tol = 1e-12 * duration.max(1.0);
    while state.t < duration - end_tol {
        let mut h = h_nominal.min(duration - state.t);
        if let Some(&bp) = ground.breakpoints(state.t + end_tol, state.t + h).first() {
            h = bp - state.t;
        }
        let (q0, qd0) = solver.to_modal(&state);
        let at = |tau: f64| solver.propagate(&state, &q0, &qd0, tau);
        let samples = opts.samples_per_step;
        let mut prev = state.clone();
        let mut prev_tau = 0.0;
        let mut event: Option<(f64, Snapshot)> = None;
        let fresh_slip = matches!(state.phase, Phase::Slip { .. }) && state.v_s == 0.0;
        for k in 1..=samples {
            let tau = h * k as f64 / samples as f64;
            let cur = at(tau);
            let g_prev = if prev_tau == 0.0 && fresh_slip {
                -1.0
            } else {
                solver.switching(&prev)
            };
            let g_cur = solver.switching(&cur);
            if g_prev <= 0.0 && g_cur > 0.0 {
                let f = |x: f64| solver.switching(&at(x));
                let tau_star = if prev_tau == 0.0 && fresh_slip {
                    // A slip that has just started has u̇_s = 0 at τ = 0; bracket the stop
                    // from a point just after the start, where the slip is under way.
                    let a = 1e-6 * tau;
                    let fa = f(a);
                    if fa > 0.0 {
                        a
                    } else {
                        solver.root(a, fa, tau, g_cur, &f)
                    }
                } else {
                    solver.root(prev_tau, g_prev, tau, g_cur, &f)
                };
                let snap = at(tau_star);
                track_extrema(&solver, &mut peaks, &at, prev_tau, &prev, tau_star, &snap);
                event = Some((tau_star, snap));
                break;
            }
            track_extrema(&solver, &mut peaks, &at, prev_tau, &prev, tau, &cur);
            prev = cur;
            prev_tau = tau;
        }
        let switched = event.is_some();
        let (tau_end, mut end) = match event {
            Some((t, s)) => (t, s),
            None => (h, prev),
        };
        // Outputs inside (t, t + τ_end].
        if output_dt > 0.0 {
            while next_output <= state.t + tau_end + end_tol && next_output <= duration + end_tol {
                let snap = at((next_output - state.t).max(0.0));
                record_output(&mut result, &snap);
                output_index += 1;
                next_output = output_index as f64 * output_dt;
            }
        }
        // Energy: work of the ground's friction force on the raft, ∫F u̇0 dt.
        energy.input_work += match state.phase {
            // A constant force: its work is exact.
            Phase::Slip { .. } => {
                solver.friction_force(&state)
                    * (ground.displacement(state.t + tau_end) - ground.displacement(state.t))
            }
            Phase::Stick => solver
                .quad_x
                .iter()
                .zip(&solver.quad_w)
                .map(|(&x, &w)| {
                    let s = 0.5 * tau_end * (1.0 + x);
                    let snap = at(s);
                    0.5 * tau_end * w * solver.holding_force(&snap) * ground.velocity(snap.t)
                })
                .sum(),
        };
        if let Phase::Slip { .. } = state.phase
            && b.friction.is_finite()
        {
            energy.friction_dissipated += b.friction * weight * (end.u_s - state.u_s).abs();
        }
        result.steps += 1;
        // Only phases that do not advance time at all count towards the chattering guard.
        if tau_end > opts.root_tolerance {
            zero_length_events = 0;
        }
        if switched {
            // Decide the next phase at the switching time.
            let next = match end.phase {
                Phase::Stick => Phase::Slip {
                    direction: -solver.holding_force(&end).signum(),
                },
                Phase::Slip { .. } => {
                    let stuck = Snapshot {
                        phase: Phase::Stick,
                        v_s: 0.0,
                        ..end.clone()
                    };
                    if solver.switching(&stuck) <= 0.0 {
                        Phase::Stick
                    } else {
                        Phase::Slip {
                            direction: -solver.holding_force(&stuck).signum(),
                        }
                    }
                }
            };
            if tau_end <= opts.root_tolerance {
                zero_length_events += 1;
                if zero_length_events > 20 {
                    return Err(Error::Solver {
                        time: end.t,
                        reason: "the stick-slip switching does not settle (zero-length phases)"
                            .into(),
                    });
                }
            }
            // At a switch the slip velocity is zero (a slip stops, or starts from rest).
            // It must be set so even when the phase does not change (a slip that stops
            // and at once slides on the same way): left at the root's tiny residual,
            // possibly against the slip direction, the switching function would already
            // be positive at the next step's start, no crossing would ever be found, and
            // friction would push the raft along for the rest of the run.
            end.v_s = 0.0;
            if next != end.phase {
                // Peaks on the old side of the switch are counted; now the new side.
                end.phase = next;
                offer_peaks(&solver, &mut peaks, &end);
                if result.events.len() < opts.max_events {
                    result.events.push(PhaseEvent {
                        time: end.t,
                        phase: next,
                    });
                }
            }
        }
        state = end;
        let (kinetic, strain) = stored_energy(b, ground, &state);
        most_stored = most_stored.max(kinetic + strain);
    }
    let (kinetic, strain) = stored_energy(b, ground, &state);
    energy.kinetic = kinetic;
    energy.strain = strain;
    energy.residual = energy.input_work - kinetic - strain - energy.friction_dissipated;
    energy.scale = (most_stored.max(kinetic + strain) + energy.friction_dissipated)
        .max(energy.input_work.abs());
    result.energy = energy;
    result.peaks = peaks.peaks;
    result.residual_slip = state.u_s;
    Ok(result)
}

/// Offers the values of a snapshot to the peak trackers.
fn offer_peaks(solver: &Solver<'_>, peaks: &mut PeakSet, s: &Snapshot) {
    let top = s.u_r.len() - 1;
    let p = &mut peaks.peaks;
    p.slip = p.slip.max(s.u_s.abs());
    p.roof_drift = p.roof_drift.max(s.u_r[top].abs());
    p.raft_accel = p.raft_accel.max(solver.raft_accel(s).0.abs());
    p.roof_accel = p.roof_accel.max(solver.storey_accel(s, top).0.abs());
}

/// Offers both samples and every interior extremum between them (found where the
/// derivative changes sign) to the peak trackers: the peaks are those of the continuous
/// solution, not of the samples.
fn track_extrema(
    solver: &Solver<'_>,
    peaks: &mut PeakSet,
    at: &dyn Fn(f64) -> Snapshot,
    ta: f64,
    a: &Snapshot,
    tb: f64,
    b: &Snapshot,
) {
    offer_peaks(solver, peaks, a);
    offer_peaks(solver, peaks, b);
    let top = a.u_r.len() - 1;
    // Derivatives of the tracked quantities.
    let derivs: [&dyn Fn(&Snapshot) -> f64; 4] = [
        &|s: &Snapshot| s.v_s,
        &|s: &Snapshot| s.v_r[top],
        &|s: &Snapshot| solver.raft_accel(s).1,
        &|s: &Snapshot| solver.storey_accel(s, top).1,
    ];
    for d in derivs {
        let (da, db) = (d(a), d(b));
        if da == 0.0 || db == 0.0 || (da > 0.0) == (db > 0.0) {
            continue;
        }
        // Orient so the function goes from ≤ 0 to > 0.
        let sign = if db > 0.0 { 1.0 } else { -1.0 };
        let f = |x: f64| sign * d(&at(x));
        let t = solver.root(ta, sign * da, tb, sign * db, &f);
        offer_peaks(solver, peaks, &at(t));
    }
}

/// Absolute kinetic energy and storey spring energy of a state.
fn stored_energy(b: &ShearBuilding, ground: &GroundMotion, state: &Snapshot) -> (f64, f64) {
    let vb = ground.velocity(state.t) + state.v_s;
    let mut kinetic = 0.5 * b.raft_mass * vb * vb;
    let mut strain = 0.0;
    for i in 0..b.storey_masses.len() {
        let v = vb + state.v_r[i];
        kinetic += 0.5 * b.storey_masses[i] * v * v;
        let du = if i == 0 {
            state.u_r[0]
        } else {
            state.u_r[i] - state.u_r[i - 1]
        };
        strain += 0.5 * b.storey_stiffnesses[i] * du * du;
    }
    (kinetic, strain)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-mode system (ω² = 2 ± √2 for unit masses and springs in a chain).
    fn two_modes() -> PhaseSystem {
        let m = DMatrix::identity(2, 2);
        let k = DMatrix::from_row_slice(2, 2, &[2.0, -1.0, -1.0, 1.0]);
        let b = DVector::from_element(2, -1.0);
        PhaseSystem::new(m, &k, &b, &DVector::zeros(2)).unwrap()
    }

    /// A kept step length holds what a propagation would compute from it afresh, a hit
    /// hands back those values, and past [`STEP_TRIG_SLOTS`] lengths the oldest is
    /// replaced (and computed again, to the same bits, when it comes back).
    #[test]
    fn kept_step_trigonometry_is_what_the_step_would_compute() {
        let sys = two_modes();
        let (x, w) = gauss_legendre(10);
        let quad = (x.as_slice(), w.as_slice());
        let mut cache = StepTrigCache::default();
        let tau = 0.0123;
        let big_omega = Some(7.5);
        let first = cache.get(tau, false, &sys, quad, big_omega);
        for (i, &xi) in x.iter().enumerate() {
            let s = 0.5 * tau * (1.0 + xi);
            assert_eq!(first.ground[i], (7.5 * s).sin_cos());
        }
        for (j, &omega) in sys.modal.omega.iter().enumerate() {
            let (sn, cs) = (omega * tau).sin_cos();
            assert_eq!(first.modes[j], (sn, cs, sin_cos_over(omega, tau).0));
            for (i, (&xi, &wi)) in x.iter().zip(&w).enumerate() {
                let s = 0.5 * tau * (1.0 + xi);
                assert_eq!(first.nodes[i], (s, 0.5 * tau * wi));
                assert_eq!(first.kernel[j * x.len() + i], sin_cos_over(omega, tau - s));
            }
        }
        let kept = (first.modes.clone(), first.kernel.clone());
        assert_eq!(cache.slots.len(), 1);
        let again = cache.get(tau, false, &sys, quad, big_omega);
        assert_eq!((again.modes.clone(), again.kernel.clone()), kept);
        assert_eq!(cache.slots.len(), 1, "a hit adds no slot");
        // The other phase's system is another entry, even for the same length.
        cache.get(tau, true, &sys, quad, big_omega);
        assert_eq!(cache.slots.len(), 2);
        for k in 1..STEP_TRIG_SLOTS {
            cache.get(tau * (1.0 + k as f64), false, &sys, quad, big_omega);
        }
        assert_eq!(cache.slots.len(), STEP_TRIG_SLOTS);
        assert!(
            !cache
                .slots
                .iter()
                .any(|e| e.tau_bits == tau.to_bits() && !e.slip),
            "the oldest length was replaced"
        );
        let back = cache.get(tau, false, &sys, quad, big_omega);
        assert_eq!((back.modes.clone(), back.kernel.clone()), kept);
    }

    /// A harmonic ground's acceleration at a propagation's nodes, by the angle sum from
    /// the kept `sin Ωs, cos Ωs`, is the motion's own `A sin Ω(t₀ + s)` to the rounding of
    /// the phase: `Ω(t₀ + s)` is itself rounded to an ulp of its size (~1e3 rad at 100 s),
    /// ~1e-13 of A; the bound allows ten times that.
    #[test]
    fn the_harmonic_ground_at_the_nodes_is_the_motions_own() {
        let sys = two_modes();
        let (x, w) = gauss_legendre(10);
        let h = crate::ground_motion::Harmonic::from_g_hz(0.3, 2.0).unwrap();
        let ground = GroundMotion::Harmonic(h);
        let mut worst: f64 = 0.0;
        for &t0 in &[0.0, 0.37, 12.3456, 99.99] {
            let tau = 0.0123;
            let mut cache = StepTrigCache::default();
            let trig = cache.get(tau, false, &sys, (&x, &w), Some(h.omega));
            assert_eq!(trig.ground.len(), trig.nodes.len());
            let (sin0, cos0) = (h.omega * t0).sin_cos();
            for (&(s, _), &(sn, cs)) in trig.nodes.iter().zip(&trig.ground) {
                let by_sum = h.amplitude * (sin0 * cs + cos0 * sn);
                worst = worst.max((by_sum - ground.accel(t0 + s)).abs());
            }
        }
        assert!(
            worst <= 1e-12 * h.amplitude,
            "{worst} against A = {}",
            h.amplitude
        );
    }
}
