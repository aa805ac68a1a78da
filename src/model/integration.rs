//! The time-integration scheme a run asks for: a choice a scene can make as well as a
//! user (see [`crate::model::Scene::integrator`]); its coefficients are the solver's
//! (`crate::dda::params`).

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// Time integration scheme. All are members of the generalised-α family
/// (Chung & Hulbert 1993), which contains Newmark's family as αm = αf = 0, written as
/// Arnold & Brüls (2007) do for constrained systems: the forces are balanced at the step's
/// end, `M q̈(n+1) = f(t(n+1))`, and the scheme's acceleration variable follows
/// `(1−αm) a(n+1) + αm a(n) = (1−αf) q̈(n+1) + αf q̈(n)`, with Newmark updates (β, γ) on
/// `a` (see `dda::integrator`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Integrator {
    /// Shi's original DDA: Newmark β = ½, γ = 1. First order, strongly dissipative at high
    /// frequency and also (by O(ωΔt)) at the structure's own frequencies. The paper's scheme.
    Classic,
    /// Average acceleration (β = ¼, γ = ½): second order, no numerical dissipation at all:
    /// stiff contact springs that ring keep ringing.
    Trapezoidal,
    /// Hilber–Hughes–Taylor α-method, α ∈ [0, ⅓]: second order with dissipation that grows
    /// with frequency.
    Hht {
        /// α ∈ [0, 1/3]; 0 is the trapezoidal rule.
        alpha: f64,
    },
    /// Generalised-α with spectral radius ρ∞ at infinite frequency: second order, optimal
    /// high-frequency dissipation for a given low-frequency error. ρ∞ = 1 is trapezoidal,
    /// ρ∞ = 0 annihilates unresolved modes in one step.
    GeneralizedAlpha {
        /// Spectral radius at infinite frequency, in [0, 1].
        rho_inf: f64,
    },
}

impl Default for Integrator {
    fn default() -> Self {
        // The default for scenes that do not choose: deformable blocks have in-plane
        // modes far above anything Δt resolves, and a ground motion's jerk or an impact
        // excites them; ρ∞ = 0 annihilates them in one step, so they do not show up in
        // reported accelerations (on the fixed-base three-storey frame the base slab
        // then peaks 3 % above the ground, with ρ∞ = 0.5 10 %). The price is a larger
        // error constant on the resolved motion — on the two-block grid 6 % in the
        // slip at Ω/ω = 10 against 1 % for ρ∞ = 0.5 — which is why the two-block scene,
        // whose rigid blocks have no such modes, asks for ρ∞ = 0.5 (`Scene::integrator`).
        Integrator::GeneralizedAlpha { rho_inf: 0.0 }
    }
}

impl Integrator {
    /// Validates the scheme's parameter.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Integrator::Hht { alpha } if !(0.0..=1.0 / 3.0).contains(&alpha) => {
                Err(Error::invalid(
                    "integrator alpha",
                    format!("HHT needs alpha in [0, 1/3], got {alpha}"),
                ))
            }
            Integrator::GeneralizedAlpha { rho_inf } if !(0.0..=1.0).contains(&rho_inf) => {
                Err(Error::invalid(
                    "integrator rho_inf",
                    format!("generalised-alpha needs rho_inf in [0, 1], got {rho_inf}"),
                ))
            }
            _ => Ok(()),
        }
    }

    /// Parses the command-line spelling: `classic`, `trapezoidal`, `hht[:α]`,
    /// `generalized-alpha[:ρ∞]` (alias `gen-alpha`).
    pub fn parse(text: &str) -> Result<Self> {
        let (name, arg) = match text.split_once(':') {
            Some((n, a)) => (n, Some(a)),
            None => (text, None),
        };
        let value = |default: f64| -> Result<f64> {
            match arg {
                None => Ok(default),
                Some(a) => a
                    .parse::<f64>()
                    .map_err(|_| Error::invalid("integrator", format!("'{a}' is not a number"))),
            }
        };
        let scheme = match name {
            "classic" => Integrator::Classic,
            "trapezoidal" => Integrator::Trapezoidal,
            "hht" => Integrator::Hht { alpha: value(0.1)? },
            "generalized-alpha" | "gen-alpha" => Integrator::GeneralizedAlpha {
                rho_inf: value(0.0)?,
            },
            _ => {
                return Err(Error::Unknown {
                    kind: "integrator",
                    name: text.to_string(),
                    known: "classic, trapezoidal, hht[:alpha], generalized-alpha[:rho_inf]".into(),
                });
            }
        };
        scheme.validate()?;
        Ok(scheme)
    }

    /// The command-line spelling of this scheme.
    pub fn label(&self) -> String {
        match self {
            Integrator::Classic => "classic".into(),
            Integrator::Trapezoidal => "trapezoidal".into(),
            Integrator::Hht { alpha } => format!("hht:{alpha}"),
            Integrator::GeneralizedAlpha { rho_inf } => format!("generalized-alpha:{rho_inf}"),
        }
    }
}

/// Scene files write the scheme as the command line does (`"generalized-alpha:0.5"`).
pub(crate) mod as_text {
    use serde::{Deserialize, Deserializer, Serializer};

    use super::Integrator;

    /// Writes `Some(scheme)` as its command-line spelling.
    pub fn serialize<S: Serializer>(
        value: &Option<Integrator>,
        serializer: S,
    ) -> Result<S::Ok, S::Error> {
        match value {
            Some(scheme) => serializer.serialize_str(&scheme.label()),
            None => serializer.serialize_none(),
        }
    }

    /// Reads the command-line spelling; errors name the accepted ones.
    pub fn deserialize<'de, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<Option<Integrator>, D::Error> {
        let text = String::deserialize(deserializer)?;
        Integrator::parse(&text)
            .map(Some)
            .map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_names() {
        assert_eq!(Integrator::parse("classic").unwrap(), Integrator::Classic);
        assert_eq!(
            Integrator::parse("hht:0.2").unwrap(),
            Integrator::Hht { alpha: 0.2 }
        );
        assert!(Integrator::parse("hht:0.9").is_err());
        assert!(Integrator::parse("euler").is_err());
    }

    #[test]
    fn labels_parse_back() {
        for scheme in [
            Integrator::Classic,
            Integrator::Trapezoidal,
            Integrator::Hht { alpha: 0.1 },
            Integrator::GeneralizedAlpha { rho_inf: 0.5 },
        ] {
            assert_eq!(Integrator::parse(&scheme.label()).unwrap(), scheme);
        }
    }
}
