//! Stiff and extreme cases (issue: numerical stability). Each case runs the solver on a
//! hard configuration and asserts a physical fact — a closed form, the exact mass-spring
//! model, an invariance or a conservation law — or, where the case cannot be solved, that
//! it stops with an error saying why. The cases live in `slidebase::headless::stability`
//! so that `slidebase stability` reports exactly what these tests check.

use slidebase::headless::stability::{StabilityRow, cases};

fn run(name: &str) -> StabilityRow {
    let case = cases()
        .into_iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no stability case named '{name}'"));
    case.run()
}

fn assert_case(name: &str) {
    let row = run(name);
    assert!(!row.nan_seen, "{name}: a NaN appeared");
    assert!(
        row.passed,
        "{name}: {} — measured: {}{}",
        row.check,
        row.detail,
        if row.error.is_empty() {
            String::new()
        } else {
            format!(" — stopped: {}", row.error)
        }
    );
}

macro_rules! stability_tests {
    ($($test:ident => $name:literal,)*) => {
        $(
            #[test]
            fn $test() {
                assert_case($name);
            }
        )*

        /// Every case in the library is covered by a test here (the slow one below).
        #[test]
        fn every_case_has_a_test() {
            let mut tested = vec![$($name,)*];
            tested.push("1000 s run");
            for case in cases() {
                assert!(tested.contains(&case.name), "case '{}' has no test", case.name);
            }
        }
    };
}

stability_tests! {
    penalty_1e_minus_2_e => "penalty 1e-2 × E",
    penalty_1_e => "penalty 1 × E",
    penalty_1e2_e => "penalty 1e2 × E",
    penalty_1e4_e => "penalty 1e4 × E",
    penalty_1e6_e => "penalty 1e6 × E",
    friction_zero_leaves_the_structure_unstrained => "friction 0",
    friction_one_millionth_matches_exact => "friction 1e-6",
    friction_ten_equals_fixed_base => "friction 10 (never slides)",
    light_structure_matches_exact => "α = 0.001",
    heavy_structure_matches_exact => "α = 0.999",
    coarse_step_stays_bounded => "Ω/ω = 10 with Δt = 0.02",
    tiny_amplitude_never_slides => "amplitude 0.001 g",
    three_g_matches_exact => "amplitude 3 g",
    pacoima_dam_matches_exact => "Pacoima Dam 1.2 g record",
    stiff_structure_moves_with_its_raft => "structure 1e4 × stiffer, Δt = 0.01",
    light_blocks_same_response => "density × 1e-4",
    heavy_blocks_same_response => "density × 1e4",
    // Regression: closed contacts stayed closed up to a gap of 1e-9 of the model size and
    // could pull with p·gap (2 kN on this block), which held the block down past 0.2 g.
    rocking_starts_at_housners_threshold => "slender block: rocking onset",
    // Regression: an impact found in one open-close pass was forgotten when the contact
    // flipped open again in the next; the vertex then sank in unopposed.
    free_rocking_follows_housner => "slender block: free rocking (Housner)",
    // Regression: contacts that closed inside an impact step, and flip-limited contacts
    // left closed in tension, threw the toppled block back up (energy residual −1.2).
    overturned_block_rests_on_its_side => "slender block overturns",
    // Regression: impacts bounced back higher each time (the generalised-α scheme carried
    // the impulse's acceleration into the next step); now they are plastic.
    dropped_block_lands_and_rests => "block dropped from a 1 mm gap",
    overlapping_blocks_are_refused => "blocks overlapping at the start",
    unsupported_block_is_refused => "block with no support",
}

/// 1000 s (1e6 steps): the energy balance does not drift. Minutes in a debug build.
#[test]
#[ignore = "slow: run with --release -- --ignored"]
fn long_run_energy_does_not_drift() {
    assert_case("1000 s run");
}

/// The overturning case over a grid (9 amplitudes 0.45–1 g × Δt 1, 0.8, 0.7, 0.5 ms, the
/// trapezoidal rule and the default integrator: 72 runs of 4 s): energy cannot be made by
/// the model, and every term of the balance is booked, so each run's residual must be far
/// below its smallest dissipation (friction, at least 1.2e-2 of the energy through the run;
/// impacts 0.6–0.98): a missed term in any step of substance would show. The residual is
/// bounded at ±1e-7 (largest measured 2.4e-8; before a resolved event took the forces of
/// the contacts it opened off the accelerations, gains were bounded at 1e-5 and losses at
/// 1e-3, with 9.8e-5 measured). The trapezoidal rule creates no energy of its own, so its
/// scheme's term (what its impact and restart steps remove) may not be negative either: it
/// was in 22 of the 36 runs (down to −4.5e-3 of the input) while a loaded contact that
/// opened was redone with the classic scheme, whose term has no sign; such a step now drops
/// the contact's start force instead. The default's gains were bounded at 1e-4 (−3.1e-5 at
/// 0.75 g, 0.8 ms) until a resolved event carried on the friction its accelerations were
/// projected with. Before the landing of every fresh impact, the classic step for contacts
/// that open and the consistent friction forces, 14 trapezoidal runs gained more than 1 %
/// (worst 88 %: the block was thrown into a spin of five turns); before the tangential
/// force of contacts that open was booked (a corner sliding under 2e6 N lifting off within
/// a step), the worst gain was 1.1 % and losses reached 4.5 %. Every run must finish
/// (before an open contact closed at any penetration, a pivot corner grazing at zero force
/// flipped between a closed pass in tension and an open one a picometre deep, and 1 g at Δt
/// 1 ms stopped).
#[test]
#[ignore = "slow in a debug build: run with --release -- --ignored"]
fn a_toppling_block_gains_no_energy() {
    use slidebase::dda::Integrator;
    use slidebase::headless::stability::toppling_block_run;
    let mut stopped = Vec::new();
    for integrator in [
        Integrator::Trapezoidal,
        Integrator::GeneralizedAlpha { rho_inf: 0.0 },
    ] {
        for amplitude in [0.45, 0.5, 0.55, 0.6, 0.65, 0.7, 0.75, 0.8, 1.0] {
            for dt in [1e-3, 0.8e-3, 0.7e-3, 0.5e-3] {
                let run = format!("{} at {amplitude} g, Δt {dt:e}", integrator.label());
                let dda = match toppling_block_run(amplitude, dt, integrator) {
                    Ok(dda) => dda,
                    Err(e) => {
                        stopped.push(format!("{run}: {e}"));
                        continue;
                    }
                };
                let residual = dda.energy_residual_relative();
                assert!(
                    residual.abs() <= 1e-7,
                    "{run}: energy residual {residual:+.3e}"
                );
                let energy = dda.energy();
                if integrator == Integrator::Trapezoidal {
                    // Round-off of the exact zero of its ordinary steps aside.
                    let scheme = energy.numerical_dissipated / energy.scale();
                    assert!(scheme >= -1e-12, "{run}: the scheme's term {scheme:+.3e}");
                }
                let block = &dda.blocks()[dda.block_index("block").unwrap()];
                assert!(
                    (block.rotation.abs() - std::f64::consts::FRAC_PI_2).abs() < 0.02,
                    "{run}: rotation {:.4} rad, not on its side",
                    block.rotation
                );
            }
        }
    }
    assert!(stopped.is_empty(), "runs stopped: {stopped:#?}");
}
