//! Low-passed peaks of an acceleration history: the peak a shake-table test would report
//! (its accelerometers are low-passed, commonly at 25 Hz), robust to the spikes of single
//! steps.
//!
//! A block model's acceleration carries spikes one to three steps wide at impacts and at
//! stick events: a velocity jump taken over one step reads as Δv/Δt. Their heights depend
//! on where the event falls within its step, so on Δt, the integrator and the linear
//! solver's path to round-off; their impulses do not. Measured on `wall:22` under the
//! first 12 s of Kobe (docs/performance-log.md, "How well defined a wall's peaks are"): the
//! raw peak base acceleration was 0.52–0.84 g across two step sizes, two integrators and
//! two solver paths, the low-passed one 0.11 g in all five.
//!
//! The history is first averaged over cells of [`CELL_S`] (its piecewise-linear integral
//! over each cell: an impulse is kept whatever its width), then smoothed by a Gaussian
//! whose gain is one half-power at [`CUTOFF_HZ`]. A Gaussian, not a Butterworth filter:
//! its weights are positive and sum to one, so a low-passed peak never exceeds the raw
//! one (a Butterworth filter overshoots the jumps of a sliding base's acceleration, from
//! ±μg to the ground's: the three-storey's base peak came out 4 % above the raw one), and
//! it is symmetric, so nothing is shifted in time.

/// Width of the cells the history is averaged over, s (a sampling rate of 1 kHz).
pub const CELL_S: f64 = 1e-3;

/// Cut-off of the low-pass filter, Hz.
pub const CUTOFF_HZ: f64 = 25.0;

/// Most cells kept (2²² cells of 1 ms: 70 min of run); past it, neighbours are merged
/// and the cell doubles.
pub const MAX_CELLS: usize = 1 << 22;

/// Averages of a piecewise-linear signal over consecutive cells from its first sample:
/// each cell holds the signal's integral over it divided by its width.
#[derive(Debug, Clone)]
pub struct CellAverages {
    width: f64,
    max_cells: usize,
    start: f64,
    last: Option<(f64, f64)>,
    /// The integral over the cell being filled, so far.
    open: f64,
    cells: Vec<f64>,
}

impl CellAverages {
    /// No samples yet; cells `width` s wide (> 0), at most `max_cells` (≥ 2) of them.
    pub fn new(width: f64, max_cells: usize) -> Self {
        Self {
            width,
            max_cells: max_cells.max(2),
            start: 0.0,
            last: None,
            open: 0.0,
            cells: Vec::new(),
        }
    }

    /// Adds the value `y` at time `t` (times must not decrease; the signal is linear
    /// between samples).
    pub fn push(&mut self, t: f64, y: f64) {
        let Some((mut tp, mut yp)) = self.last else {
            self.start = t;
            self.last = Some((t, y));
            return;
        };
        let slope = if t > tp { (y - yp) / (t - tp) } else { 0.0 };
        loop {
            let cell_end = self.start + (self.cells.len() + 1) as f64 * self.width;
            if cell_end > t {
                break;
            }
            // The part of the segment in this cell closes it.
            let y_end = yp + slope * (cell_end - tp);
            self.open += 0.5 * (yp + y_end) * (cell_end - tp);
            self.cells.push(self.open / self.width);
            self.open = 0.0;
            (tp, yp) = (cell_end, y_end);
            if self.cells.len() >= self.max_cells {
                self.merge_pairs();
            }
        }
        self.open += 0.5 * (yp + y) * (t - tp);
        self.last = Some((t, y));
    }

    /// Halves the cells: each pair becomes one cell twice as wide (an odd last cell is
    /// reopened as the start of the wider one).
    fn merge_pairs(&mut self) {
        if self.cells.len() % 2 == 1 {
            let last = self.cells.pop().unwrap_or_default();
            self.open += last * self.width;
        }
        self.cells = self
            .cells
            .chunks_exact(2)
            .map(|pair| 0.5 * (pair[0] + pair[1]))
            .collect();
        self.width *= 2.0;
    }

    /// The completed cells' averages.
    pub fn cells(&self) -> &[f64] {
        &self.cells
    }

    /// The cells' width, s.
    pub fn width(&self) -> f64 {
        self.width
    }

    /// Largest |value| of the averages low-passed at [`CUTOFF_HZ`] (see the module
    /// notes); `None` when there are fewer than two cells or the cells are too wide for
    /// the cut-off (below four cells per period).
    pub fn low_passed_peak(&self) -> Option<f64> {
        let kernel = gaussian_kernel(CUTOFF_HZ, self.width)?;
        if self.cells.len() < 2 {
            return None;
        }
        let smoothed = smooth(&self.cells, &kernel);
        Some(smoothed.iter().fold(0.0_f64, |m, v| m.max(v.abs())))
    }
}

/// Half of a Gaussian kernel (the centre weight first) for samples `dt` apart, with
/// gain exp(−(2πfσ)²/2) = 1/√2 at `cutoff_hz`: σ = √(ln 2)/(2π fc). Cut at 4σ (the
/// weights beyond sum to 6e-5 of the whole); `None` below four samples per period of
/// the cut-off.
fn gaussian_kernel(cutoff_hz: f64, dt: f64) -> Option<Vec<f64>> {
    if !(cutoff_hz > 0.0 && dt > 0.0 && cutoff_hz * dt <= 0.25) {
        return None;
    }
    let sigma = std::f64::consts::LN_2.sqrt() / (2.0 * std::f64::consts::PI * cutoff_hz);
    let half_width = (4.0 * sigma / dt).ceil() as usize;
    Some(
        (0..=half_width)
            .map(|i| (-0.5 * (i as f64 * dt / sigma).powi(2)).exp())
            .collect(),
    )
}

/// `x` smoothed by the symmetric kernel `half` (centre weight first): each value is the
/// weighted mean of its neighbours, the weights normalised over those that exist (near
/// the ends, fewer), so every result is a convex combination of the samples.
///
/// Summed offset by offset over the whole series (each pass a plain multiply-add over
/// two slices, which vectorises) rather than cell by cell with a bounds test per term:
/// this runs after every building and two-block run, and cell by cell it was ~5 % of
/// the two-block's 100 s run.
fn smooth(x: &[f64], half: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut sum: Vec<f64> = x.iter().map(|v| half[0] * v).collect();
    for (k, &w) in half.iter().enumerate().skip(1).take_while(|&(k, _)| k < n) {
        // Cell i takes x[i − k] and x[i + k] where they exist.
        for (s, v) in sum[k..].iter_mut().zip(&x[..n - k]) {
            *s += w * v;
        }
        for (s, v) in sum[..n - k].iter_mut().zip(&x[k..]) {
            *s += w * v;
        }
    }
    // A cell m from the nearer end lacks the weights of the offsets beyond m on that side.
    let total = half[0] + 2.0 * half[1..].iter().sum::<f64>();
    let missing = |m: usize| half.get(m + 1..).map_or(0.0, |t| t.iter().sum::<f64>());
    for (i, s) in sum.iter_mut().enumerate() {
        let (left, right) = (i, n - 1 - i);
        let weight = if left + 1 >= half.len() && right + 1 >= half.len() {
            total
        } else {
            total - missing(left) - missing(right)
        };
        *s /= weight;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The smoothing's gain at `f`: exp(−(2πfσ)²/2), one half-power at the cut-off.
    fn gain(f: f64) -> f64 {
        let two_pi_sigma = std::f64::consts::LN_2.sqrt() / CUTOFF_HZ;
        (-0.5 * (two_pi_sigma * f).powi(2)).exp()
    }

    fn low_passed(x: &[f64]) -> Vec<f64> {
        smooth(x, &gaussian_kernel(CUTOFF_HZ, CELL_S).unwrap())
    }

    fn peak(x: &[f64]) -> f64 {
        x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn a_constant_passes_unchanged_to_the_ends() {
        let y = low_passed(&[0.3; 500]);
        assert!(y.iter().all(|v| (v - 0.3).abs() < 1e-15), "{y:?}");
    }

    /// A long sine comes out as the same sine times the Gaussian's gain, with no shift
    /// in phase: at a tenth of the cut-off, at the cut-off (1/√2) and at twice it. The
    /// tolerance is the sampled, truncated kernel's departure from the continuous one.
    #[test]
    fn a_sine_is_scaled_by_the_gain_without_a_phase_shift() {
        for f in [2.5, CUTOFF_HZ, 50.0] {
            let x: Vec<f64> = (0..4000)
                .map(|i| (2.0 * std::f64::consts::PI * f * i as f64 * CELL_S).sin())
                .collect();
            let y = low_passed(&x);
            for i in 1000..3000 {
                assert!((y[i] - gain(f) * x[i]).abs() < 2e-3, "{f} Hz, sample {i}");
            }
        }
        assert!((gain(CUTOFF_HZ) - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
    }

    /// Spikes one and three cells wide with the same impulse give the same low-passed
    /// peak within 2 % (a pulse much shorter than the kernel comes out as the kernel
    /// times its area), although their heights differ 3×; and the unit impulse's peak is
    /// the kernel's centre weight, 1/(σ√(2π)) s⁻¹.
    #[test]
    fn spikes_of_equal_impulse_give_the_same_low_passed_peak() {
        let peak_of = |width: usize| {
            let mut x = vec![0.0; 1000];
            x[500..500 + width].fill(1.0 / (width as f64 * CELL_S));
            peak(&low_passed(&x))
        };
        let (narrow, wide) = (peak_of(1), peak_of(3));
        assert!((narrow / wide - 1.0).abs() < 0.02, "{narrow} {wide}");
        let sigma = std::f64::consts::LN_2.sqrt() / (2.0 * std::f64::consts::PI * CUTOFF_HZ);
        let centre = 1.0 / (sigma * (2.0 * std::f64::consts::PI).sqrt());
        assert!((narrow / centre - 1.0).abs() < 1e-3, "{narrow} {centre}");
    }

    /// A low-passed peak never exceeds the raw one, even for the square-ish wave of a
    /// sliding base (plateaus at ±μg, jumps to the ground's acceleration).
    #[test]
    fn a_low_passed_peak_never_exceeds_the_raw_one() {
        let x: Vec<f64> = (0..3000)
            .map(|i| {
                let t = i as f64 * CELL_S;
                let ground = 3.0 * (2.0 * std::f64::consts::PI * 1.7 * t).sin();
                ground.clamp(-1.0, 1.0) + if i % 397 == 0 { 4.0 } else { 0.0 }
            })
            .collect();
        let y = low_passed(&x);
        assert!(peak(&y) <= peak(&x));
        // A one-cell spike adds its height times the centre weight, Δ/(σ√(2π)) = 0.075.
        assert!(
            peak(&y) < 1.0 + 4.0 * 0.08,
            "the spikes are smoothed: {}",
            peak(&y)
        );
        assert!(peak(&y) > 0.99, "the plateaus are kept: {}", peak(&y));
    }

    /// Cell averages keep the signal's integral: a pulse sampled unevenly (steps cut
    /// around it) integrates over the completed cells to the integral of its samples'
    /// linear interpolant, and a constant stays constant.
    #[test]
    fn cell_averages_keep_the_integral() {
        let mut cells = CellAverages::new(CELL_S, MAX_CELLS);
        let mut samples = Vec::new();
        let mut t: f64 = 0.0;
        while t < 0.1 {
            // A pulse 2 ms wide and 5 high at 50 ms on a level of 1.
            let y = (5.0 - 5.0 * ((t - 0.05).abs() / 1e-3)).max(0.0) + 1.0;
            cells.push(t, y);
            samples.push((t, y));
            t += if (t - 0.05).abs() < 3e-3 {
                1.3e-4
            } else {
                7e-4
            };
        }
        let end = cells.cells().len() as f64 * CELL_S;
        let mut exact = 0.0;
        for w in samples.windows(2) {
            let [(ta, ya), (tb, yb)] = [w[0], w[1]];
            let tb_in = tb.min(end);
            if tb_in > ta {
                let y_end = ya + (yb - ya) * (tb_in - ta) / (tb - ta);
                exact += 0.5 * (ya + y_end) * (tb_in - ta);
            }
        }
        let integral: f64 = cells.cells().iter().sum::<f64>() * CELL_S;
        assert!((integral - exact).abs() < 1e-14, "{integral} {exact}");
        assert!(exact > end + 4e-3, "the pulse is inside the cells");
        assert!(cells.cells()[..40].iter().all(|v| (v - 1.0).abs() < 1e-12));
    }

    /// Past the most cells kept, pairs merge into cells twice as wide, with the same
    /// integral.
    #[test]
    fn full_cells_merge_in_pairs() {
        let mut cells = CellAverages::new(0.1, 4);
        for i in 0..=9 {
            cells.push(i as f64 * 0.1, i as f64);
        }
        assert_eq!(cells.width(), 0.4);
        // Cells of the ramp y = 10 t over [0, 0.4), [0.4, 0.8): averages 2 and 6.
        assert_eq!(cells.cells().len(), 2);
        assert!((cells.cells()[0] - 2.0).abs() < 1e-12);
        assert!((cells.cells()[1] - 6.0).abs() < 1e-12);
    }

    /// The offset-by-offset sums are the weighted means of the definition, cell by cell,
    /// with the weights renormalised near the ends: series shorter than the kernel, as
    /// long as it, and much longer.
    #[test]
    fn smoothing_is_the_normalised_weighted_mean_of_each_cell() {
        let half = gaussian_kernel(CUTOFF_HZ, CELL_S).unwrap();
        for n in [1, 2, 5, half.len(), 2 * half.len() + 1, 300] {
            let x: Vec<f64> = (0..n).map(|i| ((i * 37 % 11) as f64 - 4.0) * 0.7).collect();
            let y = smooth(&x, &half);
            for (i, yi) in y.iter().enumerate() {
                let (mut sum, mut weight) = (0.0, 0.0);
                for (j, xj) in x.iter().enumerate() {
                    if let Some(w) = half.get(i.abs_diff(j)) {
                        sum += w * xj;
                        weight += w;
                    }
                }
                assert!(
                    (yi - sum / weight).abs() < 1e-14,
                    "n {n}, cell {i}: {yi} vs {}",
                    sum / weight
                );
            }
        }
    }

    #[test]
    fn too_coarse_or_too_short_has_no_peak() {
        assert!(gaussian_kernel(CUTOFF_HZ, 0.011).is_none());
        let mut cells = CellAverages::new(CELL_S, MAX_CELLS);
        cells.push(0.0, 1.0);
        assert_eq!(cells.low_passed_peak(), None);
    }
}
