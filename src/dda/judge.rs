//! The open-close state machine of a vertex-edge contact, as a pure function.
//!
//! Kept free of geometry and assembly so that every transition can be tested by a table
//! of cases (dda-theory §6).

/// State of one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactState {
    /// Apart: no springs, no forces.
    Open,
    /// Closed and stuck: normal and shear penalty springs.
    Locked,
    /// Closed and slipping: normal spring plus a friction force ρN opposing the slip.
    Sliding {
        /// +1 or −1: the slip direction along the edge tangent.
        direction: f64,
    },
}

impl ContactState {
    /// Whether the normal spring is active.
    pub fn is_closed(&self) -> bool {
        !matches!(self, ContactState::Open)
    }

    /// A small integer code (0 open, 1 locked, 2 sliding) for compact state transfer.
    pub fn code(&self) -> u8 {
        match self {
            ContactState::Open => 0,
            ContactState::Locked => 1,
            ContactState::Sliding { .. } => 2,
        }
    }
}

/// What the judge needs to know about a contact at the end of a trial solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JudgeInput {
    /// The state this trial solution was assembled with.
    pub state: ContactState,
    /// Normal gap at the end of the step, m (negative = penetration).
    pub gap: f64,
    /// Shear spring force at the end of the step, N (meaningful when `state` is Locked).
    pub shear_force: f64,
    /// Normal force magnitude at the end of the step, N (≥ 0).
    pub normal_force: f64,
    /// The law's sticking coefficient (μ_s, μ_slow or Coulomb's ρ; may be +∞).
    pub friction: f64,
    /// Tangential slip of the vertex relative to the edge in this step, m.
    pub slip_increment: f64,
    /// Tangential slip velocity at the end of the step, m/s.
    pub slip_velocity: f64,
    /// A bonded joint never opens or slides.
    pub bonded: bool,
    /// A closed contact opens only when the gap exceeds this (small, > 0) value, and an
    /// open one closes only when the gap is below its negative: a little hysteresis so
    /// that a contact resting at zero force does not flicker.
    pub open_tolerance: f64,
    /// Slip reversals smaller than this (m) are not reversals: round-off, not physics.
    pub slip_tolerance: f64,
    /// The surface under the vertex is curved (a dish): a contact closing on it is
    /// judged by Coulomb's law at once (see [`judge`]).
    pub curved: bool,
}

/// Decides the state a contact should have, given a trial solution.
///
/// - Open → Locked when the vertex penetrates beyond the tolerance (gap < −tolerance:
///   the same hysteresis as for opening, so that a vertex grazing at zero force settles
///   open instead of flipping between a closed pass in tension and an open one a
///   picometre deep — a toppling block's pivot corner did that down to any Δt).
///   On a curved surface the closing pass's forces (the penetration's and the trial
///   slip's springs) are weighed first, and a shear beyond ρN closes sliding: a rigid
///   slider landing on two points of a dish cannot reach the circle at both without
///   slipping (each corner moves by about the gap times the tangent of its angle), so
///   both closed stuck ask for a gap and a slip that no rigid motion gives. The
///   multipliers of such a pair grew without bound, pulled the corners into tension and
///   open again, and the passes alternated (a slider on a 0.5 m dish under the
///   trapezoidal rule stopped 24 s into El Centro).
/// - Closed → Open when the gap opens beyond the tolerance (no tension in contacts).
/// - Locked → Sliding when the shear spring force exceeds ρN, slipping the way the
///   spring was pulled.
/// - Sliding → Locked when the slip increment reverses against the assumed direction:
///   friction stopped the vertex within the step.
/// - ρ = 0: a closed contact always slides (there is nothing to hold it).
/// - Bonded: always Locked.
pub fn judge(input: &JudgeInput) -> ContactState {
    if input.bonded {
        return ContactState::Locked;
    }
    let closed = match input.state {
        ContactState::Open => input.gap < -input.open_tolerance,
        _ => input.gap <= input.open_tolerance,
    };
    if !closed {
        return ContactState::Open;
    }
    if input.friction == 0.0 {
        let direction = match input.state {
            ContactState::Sliding { direction } if input.slip_increment == 0.0 => direction,
            _ => sign_or_plus(input.slip_increment),
        };
        return ContactState::Sliding { direction };
    }
    match input.state {
        // A contact that has just closed on a curved surface: as a locked one whose
        // spring took the pass's slip (see above).
        ContactState::Open if input.curved => coulomb(input),
        // A contact that has just closed starts locked: its shear spring takes the
        // tangential motion from this step on.
        ContactState::Open => ContactState::Locked,
        // Infinite friction (a fixed base) holds any force, even with N = 0.
        ContactState::Locked if input.friction.is_infinite() => ContactState::Locked,
        ContactState::Locked => coulomb(input),
        ContactState::Sliding { direction } => {
            if input.slip_increment * direction < -input.slip_tolerance {
                ContactState::Locked
            } else {
                ContactState::Sliding { direction }
            }
        }
    }
}

/// Coulomb's law on a stuck contact's spring: sliding the way it was pulled when its
/// force exceeds ρN, else stuck.
fn coulomb(input: &JudgeInput) -> ContactState {
    let limit = input.friction * input.normal_force;
    if input.shear_force.abs() > limit * (1.0 + 1e-12) {
        ContactState::Sliding {
            direction: sign_or_plus(input.shear_force),
        }
    } else {
        ContactState::Locked
    }
}

fn sign_or_plus(x: f64) -> f64 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ContactState::*;

    fn input(state: ContactState) -> JudgeInput {
        JudgeInput {
            state,
            gap: -1e-6,
            shear_force: 0.0,
            normal_force: 100.0,
            friction: 0.5,
            slip_increment: 0.0,
            slip_velocity: 0.0,
            bonded: false,
            open_tolerance: 1e-9,
            slip_tolerance: 1e-12,
            curved: false,
        }
    }

    #[test]
    fn transition_table() {
        let s = |d: f64| Sliding { direction: d };
        // (description, input, expected)
        let cases: Vec<(&str, JudgeInput, ContactState)> = vec![
            (
                "open stays open when apart",
                JudgeInput {
                    gap: 1e-3,
                    ..input(Open)
                },
                Open,
            ),
            (
                "open closes on penetration beyond the tolerance",
                JudgeInput {
                    gap: -2e-9,
                    ..input(Open)
                },
                Locked,
            ),
            (
                "open closes sliding on a curve when the closing pass's shear exceeds ρN",
                JudgeInput {
                    gap: -2e-9,
                    shear_force: -51.0,
                    curved: true,
                    ..input(Open)
                },
                s(-1.0),
            ),
            (
                "open closes stuck on a curve within ρN",
                JudgeInput {
                    gap: -2e-9,
                    shear_force: 49.0,
                    curved: true,
                    ..input(Open)
                },
                Locked,
            ),
            (
                "open on a curve stays open when apart",
                JudgeInput {
                    gap: 1e-3,
                    shear_force: 1e6,
                    curved: true,
                    ..input(Open)
                },
                Open,
            ),
            (
                "open stays open within the tolerance",
                JudgeInput {
                    gap: -5e-10,
                    ..input(Open)
                },
                Open,
            ),
            (
                "open stays open at exactly zero gap",
                JudgeInput {
                    gap: 0.0,
                    ..input(Open)
                },
                Open,
            ),
            (
                "locked within hysteresis stays locked",
                JudgeInput {
                    gap: 5e-10,
                    ..input(Locked)
                },
                Locked,
            ),
            (
                "locked opens in tension",
                JudgeInput {
                    gap: 1e-6,
                    ..input(Locked)
                },
                Open,
            ),
            (
                "locked below the limit",
                JudgeInput {
                    shear_force: 49.0,
                    ..input(Locked)
                },
                Locked,
            ),
            (
                "locked at the limit",
                JudgeInput {
                    shear_force: 50.0,
                    ..input(Locked)
                },
                Locked,
            ),
            (
                "locked above the limit slides +",
                JudgeInput {
                    shear_force: 51.0,
                    ..input(Locked)
                },
                s(1.0),
            ),
            (
                "locked above the limit slides −",
                JudgeInput {
                    shear_force: -51.0,
                    ..input(Locked)
                },
                s(-1.0),
            ),
            (
                "sliding keeps going",
                JudgeInput {
                    slip_increment: 1e-4,
                    ..input(s(1.0))
                },
                s(1.0),
            ),
            (
                "sliding reverses → locked",
                JudgeInput {
                    slip_increment: -1e-4,
                    ..input(s(1.0))
                },
                Locked,
            ),
            (
                "sliding − reverses → locked",
                JudgeInput {
                    slip_increment: 1e-4,
                    ..input(s(-1.0))
                },
                Locked,
            ),
            (
                "tiny reversal is round-off",
                JudgeInput {
                    slip_increment: -1e-13,
                    ..input(s(1.0))
                },
                s(1.0),
            ),
            (
                "sliding opens",
                JudgeInput {
                    gap: 1e-3,
                    ..input(s(1.0))
                },
                Open,
            ),
            (
                "frictionless always slides",
                JudgeInput {
                    friction: 0.0,
                    slip_increment: -2e-5,
                    ..input(Locked)
                },
                s(-1.0),
            ),
            (
                "frictionless open stays open",
                JudgeInput {
                    friction: 0.0,
                    gap: 1.0,
                    ..input(Open)
                },
                Open,
            ),
            (
                "infinite friction never slides",
                JudgeInput {
                    friction: f64::INFINITY,
                    shear_force: 1e30,
                    ..input(Locked)
                },
                Locked,
            ),
            (
                "bonded never opens",
                JudgeInput {
                    bonded: true,
                    gap: 1.0,
                    ..input(Locked)
                },
                Locked,
            ),
        ];
        for (what, inp, expected) in cases {
            assert_eq!(judge(&inp), expected, "{what}");
        }
    }
}
