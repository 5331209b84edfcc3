//! The contact of the current state, for the run's outputs: [`Simulation::contact`] with the surfaces,
//! [`Simulation::wire_contact`] between the wires; and when the wires first touched each other,
//! [`Simulation::wire_touch`].
//!
//! Why an accessor of the simulation: the recorders (history, snapshots, recording, charts) see a run only
//! through the [`Simulation`] their observer calls are given, and what contact did is not a function of the
//! state alone — the pressure at a point depends on the term's augmented-Lagrange multipliers and the surfaces
//! on the time the term was prepared for — so the contact term, which owns both, makes the report, and the
//! simulation hands it over with the state and the integration weights it keeps.

use super::Simulation;
use crate::solver::terms::contact::{ContactReport, SurfaceContact};
use crate::solver::terms::crossing::{WireCrossing, WireTouch};
use crate::solver::terms::wires::{WireContact, WireContactReport};

impl Simulation<'_> {
    /// The contact of the current (last converged) state with every obstacle of the model
    /// ([`crate::solver::terms::contact::ContactReport`]); `None` for a model without contact.
    pub fn contact(&self) -> Option<ContactReport> {
        let term = self
            .terms
            .iter()
            .find_map(|t| t.as_any()?.downcast_ref::<SurfaceContact>())?;
        Some(term.report(
            &self.disc,
            &self.solution.state,
            self.measures.point_weights(self.model, &self.disc),
        ))
    }

    /// When and where the device's wires first touched each other in the steps so far
    /// ([`crate::solver::terms::crossing::WireCrossing::first_touch`]); `None` if they have not.
    pub fn wire_touch(&self) -> Option<WireTouch> {
        self.terms
            .iter()
            .find_map(|t| t.as_any()?.downcast_ref::<WireCrossing>())?
            .first_touch()
    }

    /// When the device's wires first passed through each other in the steps so far (beyond the check's tolerance,
    /// [`crate::solver::terms::crossing::WireCrossing::first_crossing`]); `None` if they have not.
    pub fn wires_crossed(&self) -> Option<crate::math::Real> {
        self.terms
            .iter()
            .find_map(|t| t.as_any()?.downcast_ref::<WireCrossing>())?
            .first_crossing()
    }

    /// What the contact between the device's wires does in the current state
    /// ([`crate::solver::terms::wires::WireContactReport`]); `None` without it (`contact: {wires: true}`).
    pub fn wire_contact(&self) -> Option<WireContactReport> {
        let term = (self.terms.iter()).find_map(|t| t.as_any()?.downcast_ref::<WireContact>())?;
        Some(term.report(&self.disc, &self.solution.state))
    }
}
