//! The checks of a run specification, before and after its set-up: parameter ranges,
//! options that do not apply to the scene or model (refused, never ignored), the size of
//! the run against the limits, and whether Δt resolves what it must.

use super::prepare::RunSetup;
use super::spec::{ExcitationSpec, Frequency, ModelKind, RunSpec};
use crate::error::{require_range, show};
use crate::ground_motion::GroundMotion;
use crate::limits::{
    FREQUENCY_RANGE_HZ, MAX_ACCEL_G, MAX_FRICTION, MAX_STEPS, MIN_AMPLITUDE_G,
    MIN_STEPS_PER_PERIOD, WARN_STEPS_PER_PERIOD,
};
use crate::model::Scene;
use crate::{Error, Result};

/// Ranges of the parameters the specification sets, named by their flags.
pub(super) fn check_ranges(spec: &RunSpec) -> Result<()> {
    if let Some(dt) = spec.dt {
        crate::error::require_positive("--dt", dt)?;
    }
    if let Some(d) = spec.duration {
        crate::error::require_positive("--duration", d)?;
    }
    if let Some(a) = spec.alpha {
        crate::model::presets::check_alpha(a)?;
    }
    if spec.friction.is_some() && spec.friction_law.is_some() {
        return Err(Error::invalid(
            "--friction-law",
            "conflicts with --friction: give the joint one law (--friction ρ is \
             --friction-law coulomb:ρ)",
        ));
    }
    if spec.fixed_base && spec.friction_law.is_some() {
        return Err(Error::invalid(
            "--friction-law",
            "conflicts with --fixed-base: a fixed base never slides, whatever its law",
        ));
    }
    if let Some(law) = spec.friction_law {
        law.check()
            .map_err(|e| Error::invalid("--friction-law", e))?;
        // As for --friction inf: the flag sets how a joint slides, not that it never does.
        if crate::model::friction::FrictionLaw::sticking_coefficient(&law) == f64::INFINITY {
            return Err(Error::invalid(
                "--friction-law",
                "an infinite coefficient: a joint that never slides is --fixed-base",
            ));
        }
    }
    if let Some(f) = spec.friction {
        if f == f64::INFINITY {
            return Err(Error::invalid(
                "--friction",
                "inf: a joint that never slides is --fixed-base",
            ));
        }
        require_range("--friction", f, 0.0, MAX_FRICTION, "")?;
    }
    if let Some(i) = spec.integrator {
        i.validate()?;
    }
    if let Some(pga) = spec.pga_g {
        require_range("--pga", pga, MIN_AMPLITUDE_G, MAX_ACCEL_G, "g")?;
    }
    match &spec.excitation {
        ExcitationSpec::Scene => {}
        ExcitationSpec::Harmonic {
            amplitude_g,
            frequency,
        } => {
            if let Some(a) = amplitude_g {
                require_range("--amplitude-g", *a, MIN_AMPLITUDE_G, MAX_ACCEL_G, "g")?;
            }
            match frequency {
                Some(Frequency::Ratio(r)) => {
                    crate::error::require_positive("--freq-ratio", *r)?;
                }
                Some(Frequency::Hz(f)) => {
                    let (lo, hi) = FREQUENCY_RANGE_HZ;
                    require_range("frequency", *f, lo, hi, "Hz")?;
                }
                None => {}
            }
        }
        ExcitationSpec::Record { source, scale } => {
            if source.trim().is_empty() {
                return Err(Error::invalid("--record", "names no record"));
            }
            require_range("record scale", *scale, 1e-6, 1e3, "")?;
        }
    }
    Ok(())
}

/// Structural damping applies to a two-block scene (the dashpot beside its spring) and to
/// a building whose structure is one elastic body, its blocks joined by connection
/// elements or bolts (Rayleigh damping). A structure of blocks in contact (a masonry wall)
/// is refused: Rayleigh's mass-proportional part would damp the blocks' sliding and
/// rocking on each other, which is friction's to dissipate.
fn check_damping_applies(scene: &Scene) -> Result<()> {
    if scene.two_block.is_some() {
        return Ok(());
    }
    let Some(roles) = &scene.structure else {
        return Err(Error::invalid(
            "--damping",
            format!(
                "structural damping applies to two-block scenes (a dashpot beside the \
                 spring) and building scenes (Rayleigh damping of the frame); '{}' is \
                 neither (a rigid block has no structure to damp)",
                scene.name
            ),
        ));
    };
    if let Some(c) = super::modes::contact_within_structure(scene, roles) {
        return Err(Error::invalid(
            "--damping",
            format!(
                "Rayleigh damping needs a structure that is one elastic body (blocks joined \
                 by connection elements, as the frame scenes are); '{}' has blocks in \
                 contact (contact {}), whose sliding and rocking on each other the \
                 damping would resist",
                scene.name,
                c.label()
            ),
        ));
    }
    Ok(())
}

/// Options that do not apply to this scene and model: refused, with what would apply.
pub(super) fn check_applicable(spec: &RunSpec, scene: &Scene) -> Result<()> {
    let exact = spec.model == ModelKind::MassSpring;
    if exact {
        let why = "the exact mass-spring model has no time step, integrator or ground \
                   block (it steps from event to event); it applies to --model dda";
        for (given, flag) in [
            (spec.dt.is_some(), "--dt"),
            (spec.integrator.is_some(), "--integrator"),
            (spec.ground.is_some(), "--ground"),
        ] {
            if given {
                return Err(Error::invalid(flag, why));
            }
        }
    }
    if let Some(zeta) = spec.damping {
        crate::error::require_range("--damping", zeta, 0.0, 0.99, "(the damping ratio ζ)")?;
        check_damping_applies(scene)?;
    }
    // `--bearing flat` too: it names the bearing under a frame's base slab, and a scene
    // without one would silently ignore it.
    if spec.bearing.is_some() && scene.structure.is_none() {
        return Err(Error::invalid(
            "--bearing",
            format!(
                "bearings go under a frame's base slab (three-storey, frame:N); '{}' is \
                 not a frame (for a lone slider on a dish, run --scene friction-pendulum)",
                scene.name
            ),
        ));
    }
    if spec.fixed_base && spec.bearing.is_some_and(|b| b.radius().is_some()) {
        return Err(Error::invalid(
            "--bearing",
            "conflicts with --fixed-base: a base fixed to the ground sits on no bearing \
             (run once with each to compare them)",
        ));
    }
    if spec.fixed_base && spec.friction.is_some() {
        return Err(Error::invalid(
            "--friction",
            "conflicts with --fixed-base: a fixed base never slides, whatever its friction",
        ));
    }
    let building = scene.two_block.is_none();
    if building {
        if spec.alpha.is_some() {
            return Err(Error::invalid(
                "--alpha",
                format!(
                    "sets the mass ratio of the two-block scene; '{}' is not one (its \
                     masses are its blocks')",
                    scene.name
                ),
            ));
        }
        if let ExcitationSpec::Harmonic {
            amplitude_g: Some(_),
            frequency: None,
        } = &spec.excitation
            && !matches!(
                scene.excitation,
                crate::model::scene::ExcitationDef::Harmonic { .. }
            )
        {
            return Err(Error::invalid(
                "--amplitude-g",
                format!(
                    "sets the amplitude of harmonic input, but '{}' runs a record; scale a \
                     record with `scale` in the scene's [excitation]",
                    scene.name
                ),
            ));
        }
    }
    Ok(())
}

/// The number of steps the exact model takes: a 32nd of the shortest period of the stick
/// and slip phases or the excitation (a 1000th for the stepped solution), and every
/// record sample.
fn exact_steps(setup: &RunSetup) -> Option<f64> {
    if let super::SceneRoles::Block(_) = setup.roles {
        return Some(
            setup
                .sliding_block()
                .steps(setup.duration, &Default::default()),
        );
    }
    let (roles, alpha, _) = setup.two_block()?;
    if setup.needs_stepped_exact() {
        let structure = setup.two_block_structure()?.ok()?;
        return Some(structure.steps(setup.duration, &Default::default()));
    }
    // The slip phase's structure frequency ω/√(1 − α) is the higher one.
    let structure = roles.structure_frequency_hz / (1.0 - alpha).sqrt();
    Some(exact_steps_for(structure, &setup.motion, setup.duration))
}

/// The exact model's steps for a highest natural frequency `f_max` (Hz).
pub fn exact_steps_for(f_max: f64, motion: &GroundMotion, duration: f64) -> f64 {
    let excitation = match motion {
        GroundMotion::Harmonic(h) => h.omega / (2.0 * std::f64::consts::PI),
        GroundMotion::Record(_) => 0.0,
    };
    let samples = match motion {
        GroundMotion::Record(r) => duration.min(r.duration()) / r.dt,
        GroundMotion::Harmonic(_) => 0.0,
    };
    32.0 * duration * f_max.max(excitation) + samples
}

/// Refuses a run whose step count is beyond [`MAX_STEPS`] unless confirmed.
pub fn check_steps(steps: f64, what: &str, confirmed: bool) -> Result<()> {
    if steps > MAX_STEPS && !confirmed {
        // The fastest model (two blocks) takes about 3e5 steps per second.
        let hours = match steps / 3e5 / 3600.0 {
            h if h < 1e5 => format!("{h:.1}"),
            h => format!("{h:.1e}"),
        };
        return Err(Error::invalid(
            "--duration/--dt",
            format!(
                "{what} would take {steps:.3e} steps, beyond the limit of {MAX_STEPS:e} \
                 (at least {hours} h of computing at the two-block model's 3e5 steps/s); \
                 shorten --duration, enlarge --dt, or give --confirm-large to run it anyway"
            ),
        ));
    }
    Ok(())
}

/// The size and resolution checks of a set-up: refusals as errors, the rest as warnings.
pub(super) fn check_setup(setup: &RunSetup, confirmed: bool) -> Result<Vec<String>> {
    let mut warnings = Vec::new();
    if let GroundMotion::Record(r) = &setup.motion {
        if r.is_vertical() {
            return Err(Error::invalid(
                "--record",
                format!(
                    "'{}' is a vertical component (its header says so) and --record is the \
                     horizontal input: use a horizontal component there, and give this one \
                     as --vertical-record",
                    r.name
                ),
            ));
        }
        let peak = r.peak_accel(r.duration());
        if peak < MIN_AMPLITUDE_G * crate::ground_motion::STANDARD_GRAVITY {
            return Err(Error::record(
                &r.source,
                0,
                format!(
                    "its largest acceleration is {:.3e} g, below {MIN_AMPLITUDE_G:e} g: no \
                     ground motion to run",
                    peak / crate::ground_motion::STANDARD_GRAVITY
                ),
            ));
        }
    }
    if let Some(vertical) = &setup.vertical {
        check_vertical(setup, vertical, &mut warnings)?;
    }
    match setup.model {
        ModelKind::Dda => {
            let steps = setup.duration / setup.dt;
            check_steps(steps, "the run", confirmed)?;
            if setup.duration < setup.dt {
                return Err(Error::invalid(
                    "--duration",
                    format!(
                        "{} s is shorter than one time step Δt = {} s",
                        setup.duration, setup.dt
                    ),
                ));
            }
            resolution(setup, &mut warnings)?;
            warnings.extend(fast_ground(setup, confirmed)?);
        }
        ModelKind::MassSpring => {
            if let Some(steps) = exact_steps(setup) {
                check_steps(steps, "the exact model", confirmed)?;
            }
        }
    }
    Ok(warnings)
}

/// A ground so fast that a base it drags along would move further in one Δt than the
/// solver lets a vertex move in a step (`max_displacement_ratio` of the structure's size):
/// every such step is cut, and a run asked for in 1e5 steps takes millions. Said before
/// the run, with the step it will take; refused (unless confirmed) when those steps would
/// pass [`MAX_STEPS`], as a run asked for in that many steps is.
fn fast_ground(setup: &RunSetup, confirmed: bool) -> Result<Option<String>> {
    if setup.fixed_base || setup.friction.is_infinite() {
        return Ok(None);
    }
    let size = setup.scene.structure_size();
    let ratio = setup.solver_params().max_displacement_ratio;
    let speed = setup.motion.peak_velocity(setup.duration);
    let step = ratio * size / speed;
    let steps = setup.duration / step;
    if step < setup.dt && steps > MAX_STEPS && !confirmed {
        return Err(Error::invalid(
            "--amplitude-g/--freq-ratio/--duration",
            format!(
                "the ground reaches {speed:.3e} m/s, so the run's steps would be cut to about \
                 {step:.2e} s to follow a base it drags along: {steps:.2e} steps, beyond the \
                 limit of {MAX_STEPS:e}; lower the amplitude, raise the frequency, shorten \
                 --duration, or give --confirm-large to run it anyway"
            ),
        ));
    }
    Ok((step < setup.dt).then(|| {
        format!(
            "the ground reaches {speed:.3e} m/s: a base it drags along would move {:.3} of \
             the structure's size in one Δt = {} s, beyond the step limit of {ratio}, so \
             steps are cut to about {step:.2e} s (up to {:.1e} steps instead of {:.1e}); \
             lower the amplitude or raise the frequency for a run of the asked length",
            speed * setup.dt / size,
            show(setup.dt),
            steps,
            setup.duration / setup.dt,
        )
    }))
}

/// Vertical shaking: where it applies, whether its record is a vertical one, and when it
/// lifts the structure off the ground.
fn check_vertical(
    setup: &RunSetup,
    vertical: &GroundMotion,
    warnings: &mut Vec<String>,
) -> Result<()> {
    if setup.scene.ground.kind == crate::model::scene::GroundKind::LargeMass {
        return Err(Error::invalid(
            "--vertical-record",
            "the large-mass ground rides on vertical rollers and is driven horizontally \
             only; vertical shaking needs --ground prescribed",
        ));
    }
    if let GroundMotion::Record(r) = vertical
        && !r.is_vertical()
    {
        warnings.push(format!(
            "the vertical record '{}' is not marked as a vertical component (its header \
             names no UP/DOWN/VERTICAL component); it is used as one",
            r.name
        ));
    }
    if let Some((t, a)) = first_lift_off(vertical, setup.scene.gravity, setup.duration) {
        let g = crate::ground_motion::STANDARD_GRAVITY;
        let what = format!(
            "the vertical ground acceleration passes gravity downward at t = {t:.3} s \
             (reaching {} g): the structure lifts off the ground there",
            above_in_print(-a / g, setup.scene.gravity / g)
        );
        if setup.model == ModelKind::MassSpring {
            return Err(Error::invalid(
                "--vertical-scale",
                format!("{what}; the mass-spring model stays on the ground: lower the scale"),
            ));
        }
        warnings.push(format!(
            "{what}; the joint opens and DDA follows the flight and the landing"
        ));
    }
    Ok(())
}

/// The first time in [0, duration] when the ground accelerates downward faster than
/// gravity (g + a_v ≤ 0), and a_v at the sample where it has (the crossing itself is
/// exactly −g); records are piecewise linear, so their samples bound it.
fn first_lift_off(vertical: &GroundMotion, gravity: f64, duration: f64) -> Option<(f64, f64)> {
    let times: Vec<f64> = std::iter::once(0.0)
        .chain(vertical.breakpoints(0.0, duration))
        .chain(std::iter::once(duration))
        .collect();
    times.windows(2).find_map(|w| {
        let (a0, a1) = (vertical.accel(w[0]), vertical.accel(w[1]));
        if gravity + a0 <= 0.0 {
            return Some((w[0], a0));
        }
        // Linear in between: where it crosses −g.
        (gravity + a1 <= 0.0).then(|| {
            let t = w[0] + (w[1] - w[0]) * (gravity + a0) / (a0 - a1);
            (t, a1)
        })
    })
}

/// Δt against the shortest relevant periods: the excitation's, the two-block structure's
/// (slip phase) and the record's sampling.
fn resolution(setup: &RunSetup, warnings: &mut Vec<String>) -> Result<()> {
    let dt = setup.dt;
    let dts = show(dt);
    let mut periods: Vec<(f64, String)> = Vec::new();
    if let GroundMotion::Harmonic(h) = &setup.motion {
        periods.push((
            2.0 * std::f64::consts::PI / h.omega,
            "the excitation's period".into(),
        ));
    }
    if let Some((roles, alpha, _)) = setup.two_block() {
        let f = roles.structure_frequency_hz / (1.0 - alpha).sqrt();
        periods.push((1.0 / f, "the structure's period (slip phase)".into()));
    }
    for (period, what) in periods {
        let per = period / dt;
        if per < MIN_STEPS_PER_PERIOD {
            return Err(Error::invalid(
                "--dt",
                format!(
                    "Δt = {dts} s is {per:.3} steps per {what} ({period:.4e} s): the motion \
                     cannot be represented below {MIN_STEPS_PER_PERIOD} steps a period (Δt <= \
                     {:.3e} s is accepted, Δt <= {:.3e} s resolves it)",
                    period / MIN_STEPS_PER_PERIOD,
                    period / WARN_STEPS_PER_PERIOD
                ),
            ));
        }
        if per < WARN_STEPS_PER_PERIOD {
            warnings.push(format!(
                "Δt = {dts} s gives only {per:.1} steps per {what} ({period:.4e} s); results \
                 are not resolved below Δt = {:.3e} s",
                period / WARN_STEPS_PER_PERIOD
            ));
        }
    }
    if let GroundMotion::Record(r) = &setup.motion {
        if dt > 5.0 * r.dt {
            return Err(Error::invalid(
                "--dt",
                format!(
                    "Δt = {dts} s skips more than 4 of every 5 samples of record '{}' \
                     (sampled every {} s); use Δt <= {} s",
                    r.name, r.dt, r.dt
                ),
            ));
        }
        if dt > r.dt {
            warnings.push(format!(
                "Δt = {dts} s is coarser than the sampling of record '{}' ({} s): the \
                 samples between steps are not seen",
                r.name, r.dt
            ));
        }
    }
    Ok(())
}

/// `value` printed with three decimals, or as many more (up to nine) as show it above
/// `limit`: a record peaking at 1.0004 g is not said to reach "1.000 g, more than gravity".
fn above_in_print(value: f64, limit: f64) -> String {
    let shown = |d: usize| format!("{value:.d$}");
    let exceeds = |d: usize| shown(d).parse::<f64>().is_ok_and(|v| v > limit);
    shown((3..=9).find(|&d| exceeds(d)).unwrap_or(9))
}

#[cfg(test)]
mod tests {
    /// A peak just above gravity is printed above it, a clear one with three decimals.
    #[test]
    fn a_value_just_above_its_limit_is_printed_above_it() {
        assert_eq!(super::above_in_print(1.0004, 1.0), "1.0004");
        assert_eq!(super::above_in_print(1.5, 1.0), "1.500");
    }
}
