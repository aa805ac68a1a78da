//! Friction laws of a joint, as data: what a scene file or the command line declares.
//!
//! A law says how much tangential force a closed joint holds while stuck (the sticking
//! coefficient, times the normal force) and how much it carries while slipping (the
//! sliding coefficient, which may depend on the slip speed). The solver asks exactly these
//! questions, through the [`FrictionLaw`] trait, so that the judge, the assembly, the event
//! resolution and the energy ledger never look at a law's parameters: a new law is a new
//! variant here and its answers in the trait's implementation.
//!
//! Written forms (the same in TOML and on the command line):
//!
//! - a number `0.1`, or `coulomb:0.1`: Coulomb friction, static = kinetic (the paper's);
//!   `inf` never slides;
//! - `static-kinetic:MU_S,MU_K`: sticks up to μ_s·N, slides against μ_k·N (μ_k ≤ μ_s);
//! - `velocity:MU_SLOW,MU_FAST,RATE`: μ(v) = μ_fast − (μ_fast − μ_slow)·exp(−RATE·|v|),
//!   v the slip speed in m/s and RATE in s/m (OpenSees' `VelDependent` friction model);
//!   it sticks up to μ_slow·N.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::limits::MAX_FRICTION;

/// Largest rate of the velocity law, s/m: 1e6 s/m reaches μ_fast within microns per second.
pub const MAX_RATE: f64 = 1e6;

/// The friction law of a joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Friction {
    /// Coulomb: one coefficient ρ for sticking and sliding (may be +∞: never slides).
    Coulomb(f64),
    /// Static and kinetic coefficients: sticks up to `stick`·N, slides against `slide`·N.
    StaticKinetic {
        /// Static coefficient μ_s.
        stick: f64,
        /// Kinetic coefficient μ_k ≤ μ_s.
        slide: f64,
    },
    /// Velocity dependent: μ(v) = fast − (fast − slow)·exp(−rate·|v|); sticks up to
    /// `slow`·N.
    Velocity {
        /// Coefficient at zero slip speed, μ_slow.
        slow: f64,
        /// Coefficient at high slip speed, μ_fast.
        fast: f64,
        /// Rate, s/m.
        rate: f64,
    },
}

/// A friction law as the solver sees it.
///
/// The open-close judge compares a stuck contact's tangential force with the sticking
/// coefficient times N; a sliding contact carries the sliding coefficient at its slip speed
/// times N, evaluated at the step's end (where the integrator balances the forces) and
/// iterated within the step like the normal force it multiplies (docs/friction-laws.md).
pub trait FrictionLaw {
    /// Coefficient of the largest tangential force a stuck contact holds, per unit normal
    /// force (+∞: never slides; 0: always slides).
    fn sticking_coefficient(&self) -> f64;

    /// Coefficient of the friction force of a contact slipping at `slip_speed` (m/s, either
    /// sign), per unit normal force; finite.
    fn sliding_coefficient(&self, slip_speed: f64) -> f64;

    /// Whether the sliding coefficient changes with the slip speed: a sliding contact then
    /// keeps the coefficient its step was solved with, so that the next step starts from
    /// the force this one applied and booked (the open-close iteration waits for the
    /// coefficient to settle for every law).
    fn depends_on_speed(&self) -> bool;
}

impl FrictionLaw for Friction {
    fn sticking_coefficient(&self) -> f64 {
        match *self {
            Friction::Coulomb(mu) => mu,
            Friction::StaticKinetic { stick, .. } => stick,
            Friction::Velocity { slow, .. } => slow,
        }
    }

    /// A joint that never slides (`inf`) reports 0: it can carry no sliding force.
    fn sliding_coefficient(&self, slip_speed: f64) -> f64 {
        let mu = match *self {
            Friction::Coulomb(mu) => mu,
            Friction::StaticKinetic { slide, .. } => slide,
            Friction::Velocity { slow, fast, rate } => {
                fast - (fast - slow) * (-rate * slip_speed.abs()).exp()
            }
        };
        if mu.is_finite() { mu } else { 0.0 }
    }

    fn depends_on_speed(&self) -> bool {
        matches!(self, Friction::Velocity { slow, fast, .. } if slow != fast)
    }
}

impl Friction {
    /// Checks the coefficients; the message says what would be accepted.
    pub fn check(&self) -> Result<(), String> {
        let coefficient = |name: &str, mu: f64| {
            if mu.is_finite() && (0.0..=MAX_FRICTION).contains(&mu) {
                Ok(())
            } else {
                Err(format!(
                    "{name} must be in [0, {MAX_FRICTION}], got {}",
                    crate::error::show(mu)
                ))
            }
        };
        match *self {
            Friction::Coulomb(mu) if mu == f64::INFINITY => Ok(()),
            Friction::Coulomb(mu) => coefficient("the coefficient", mu)
                .map_err(|e| format!("{e} (or inf: never slides)")),
            Friction::StaticKinetic { stick, slide } => {
                coefficient("MU_S", stick)?;
                coefficient("MU_K", slide)?;
                if slide > stick {
                    return Err(format!(
                        "MU_K ({slide}) must not exceed MU_S ({stick}): a joint that slides \
                         against more than it holds would stop as soon as it starts"
                    ));
                }
                Ok(())
            }
            Friction::Velocity { slow, fast, rate } => {
                coefficient("MU_SLOW", slow)?;
                coefficient("MU_FAST", fast)?;
                if !(rate.is_finite() && (0.0..=MAX_RATE).contains(&rate)) {
                    return Err(format!(
                        "RATE must be in [0, {MAX_RATE}] s/m, got {}",
                        crate::error::show(rate)
                    ));
                }
                Ok(())
            }
        }
    }
}

/// What `FromStr` accepts, for error messages.
pub const FRICTION_FORMS: &str = "a coefficient (0.1, inf), coulomb:MU, \
     static-kinetic:MU_S,MU_K or velocity:MU_SLOW,MU_FAST,RATE";

impl FromStr for Friction {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let text = text.trim();
        let (name, args) = text.split_once(':').unwrap_or(("coulomb", text));
        let numbers: Vec<f64> = args
            .split(',')
            .map(|a| {
                a.trim()
                    .parse::<f64>()
                    .map_err(|_| format!("'{}' in '{text}' is not a number", a.trim()))
            })
            .collect::<Result<_, _>>()?;
        let law = match (name.trim(), numbers.as_slice()) {
            ("coulomb", &[mu]) => Friction::Coulomb(mu),
            ("static-kinetic", &[stick, slide]) => Friction::StaticKinetic { stick, slide },
            ("velocity", &[slow, fast, rate]) => Friction::Velocity { slow, fast, rate },
            _ => {
                return Err(format!(
                    "'{text}' is not a friction law; expected {FRICTION_FORMS}"
                ));
            }
        };
        law.check().map_err(|e| format!("'{text}': {e}"))?;
        Ok(law)
    }
}

impl fmt::Display for Friction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Friction::Coulomb(mu) => write!(f, "{mu}"),
            Friction::StaticKinetic { stick, slide } => write!(f, "static-kinetic:{stick},{slide}"),
            Friction::Velocity { slow, fast, rate } => write!(f, "velocity:{slow},{fast},{rate}"),
        }
    }
}

impl Serialize for Friction {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match *self {
            Friction::Coulomb(mu) => serializer.serialize_f64(mu),
            _ => serializer.collect_str(self),
        }
    }
}

impl<'de> Deserialize<'de> for Friction {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        /// A number is a Coulomb coefficient (checked later with the scene, where the
        /// message can name the contact); a string is a law.
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Written {
            Number(f64),
            Text(String),
        }
        match Written::deserialize(deserializer)? {
            Written::Number(mu) => Ok(Friction::Coulomb(mu)),
            Written::Text(text) => text.parse().map_err(serde::de::Error::custom),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_forms_parse_and_print_back() {
        for text in [
            "0.1",
            "inf",
            "static-kinetic:0.6,0.4",
            "velocity:0.05,0.1,20",
        ] {
            let law: Friction = text.parse().unwrap();
            let again: Friction = law.to_string().parse().unwrap();
            assert_eq!(law, again, "{text}");
        }
        assert_eq!("coulomb:0.3".parse(), Ok(Friction::Coulomb(0.3)));
    }

    #[test]
    fn bad_laws_are_refused_with_the_accepted_forms() {
        for (text, says) in [
            ("static-kinetic:0.3", "expected a coefficient"),
            ("velocity:0.1,0.2", "expected a coefficient"),
            ("stribeck:0.1", "expected a coefficient"),
            ("static-kinetic:0.3,0.5", "must not exceed"),
            ("velocity:0.1,0.2,-1", "RATE"),
            ("static-kinetic:0.3,x", "not a number"),
            ("-0.1", "or inf"),
            ("nan", "or inf"),
        ] {
            let err = text.parse::<Friction>().unwrap_err();
            assert!(err.contains(says), "{text}: {err}");
        }
    }

    #[test]
    fn the_velocity_law_runs_from_slow_to_fast() {
        let law = Friction::Velocity {
            slow: 0.05,
            fast: 0.12,
            rate: 20.0,
        };
        assert_eq!(law.sticking_coefficient(), 0.05);
        assert_eq!(law.sliding_coefficient(0.0), 0.05);
        // One e-folding at v = 1/RATE, symmetric in the slip direction.
        let at = 0.12 - 0.07 * (-1.0_f64).exp();
        assert!((law.sliding_coefficient(0.05) - at).abs() < 1e-15);
        assert_eq!(
            law.sliding_coefficient(-0.05),
            law.sliding_coefficient(0.05)
        );
        assert!((law.sliding_coefficient(10.0) - 0.12).abs() < 1e-15);
    }

    #[test]
    fn a_joint_that_never_slides_carries_no_sliding_force() {
        assert_eq!(
            Friction::Coulomb(f64::INFINITY).sliding_coefficient(1.0),
            0.0
        );
        assert_eq!(
            Friction::Coulomb(f64::INFINITY).sticking_coefficient(),
            f64::INFINITY
        );
    }
}
