//! The defaults of a run, in one place. Everything not listed here comes from the scene
//! itself (α and ρ of a two-block scene, its harmonic excitation, a building's record).

/// The scene when none is named: the paper's two-mass model (Fig. 2).
pub const SCENE: &str = "two-block";

/// DDA time step, s: the paper's, ≥ 100 steps per period up to 10 Hz.
pub const DT: f64 = 1e-3;

/// Duration of a run under harmonic input, s: the paper's 100 s, long enough for the
/// stick-slip response to settle into its steady state at every Ω/ω of Figs 4–9. (A run
/// under a record lasts as long as the record.)
pub const HARMONIC_DURATION_S: f64 = 100.0;

/// Harmonic amplitude, g, when a harmonic run is asked of a scene whose own excitation
/// is not harmonic: the paper's 0.3 g.
pub const AMPLITUDE_G: f64 = 0.3;

/// Ω/ω when a harmonic run is asked of a two-block scene whose own excitation is not
/// harmonic: resonance.
pub const FREQ_RATIO: f64 = 1.0;

/// Steps between recorded history rows of a two-block run written with `--out` (10 ms at
/// the default Δt: smooth curves, a tenth of the memory of every step).
pub const TWO_BLOCK_HISTORY_EVERY: usize = 10;

/// The ground block is lengthened to this many times the ground's largest displacement
/// (plus [`GROUND_MARGIN_M`]) on each side of the structure, so that a sliding base never
/// runs off its end.
pub const GROUND_TRAVEL_FACTOR: f64 = 1.2;

/// See [`GROUND_TRAVEL_FACTOR`], m.
pub const GROUND_MARGIN_M: f64 = 10.0;

/// Samples of the ground displacement over the run from which its largest value is taken
/// (for [`GROUND_TRAVEL_FACTOR`]).
pub const GROUND_TRAVEL_SAMPLES: usize = 2000;
