//! The recorded-like data of a motion scenario: what `platen generate recorded` writes, and
//! what a manifest's `scenario` entry identifies (made in memory).

use std::path::Path;

use platen_integrate::{inverse, Motion, Peaks, Trajectory};
use platen_model::PlatenModel;
use platen_scenario::recorded::{recorded_like, ArtefactSettings, Recorded};
use platen_scenario::{Model, PlatenScenario, Run};

use crate::error::InputError;

/// The recorded-like data of a loaded motion scenario (`path` names it in messages): what
/// `platen generate recorded --seed SEED` writes.
///
/// # Errors
/// [`InputError::NotMotion`] for a force-driven scenario, [`InputError::RecordedLike`] if
/// the data cannot be made.
pub fn recorded_of(
    scenario: &PlatenScenario,
    path: &Path,
    seed: u64,
) -> Result<Recorded, InputError> {
    fn recorded<M: PlatenModel>(
        model: &M,
        motion: &Motion,
        seed: u64,
    ) -> Result<Recorded, InputError> {
        let mut truth = (Trajectory::with_capacity(motion.len()), Peaks::default());
        inverse(model, motion, &mut truth);
        recorded_like(
            &truth.0,
            model.static_threshold_n(0.0),
            &ArtefactSettings::default(),
            seed,
        )
        .map_err(|message| InputError::RecordedLike { message })
    }
    let (Run::Inverse { motion }
    | Run::ClosedLoop {
        command: motion, ..
    }) = &scenario.run
    else {
        return Err(InputError::NotMotion {
            path: path.to_owned(),
        });
    };
    match &scenario.rig.model {
        Model::Identified(m) => recorded(m, motion, seed),
        Model::Full(m) => recorded(&**m, motion, seed),
    }
}
