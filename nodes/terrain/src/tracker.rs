//! The control's memory of the feet (SPEC §6): the latest touchdown of each leg; an assessment
//! once all six are known, at every touchdown after that.

use crate::assess::{Assessment, Assessor};
use crate::error::{check_point, TerrainError};
use crate::leg::Leg;
use nalgebra::Point3;

/// Latest touchdown per leg, the last good assessment and counts of what was refused.
#[derive(Debug, Clone)]
pub struct FootTracker {
    assessor: Assessor,
    feet: [Option<Point3<f64>>; 6],
    last: Option<Assessment>,
    rejected: u64,
    failed: u64,
}

impl FootTracker {
    /// A tracker that knows no foot yet.
    pub fn new(assessor: Assessor) -> Self {
        FootTracker {
            assessor,
            feet: [None; 6],
            last: None,
            rejected: 0,
            failed: 0,
        }
    }

    /// The assessor.
    pub fn assessor(&self) -> &Assessor {
        &self.assessor
    }

    /// Records a touchdown of `leg` at `position` (m, body frame). A non-finite or
    /// out-of-range position is refused, counted in [`FootTracker::rejected`], and changes
    /// nothing. Otherwise the foot is stored and, once all six are known, assessed: `Ok(None)`
    /// while some leg has not touched down yet; a degenerate stance (e.g. three collinear feet)
    /// keeps the foot, returns the error, is counted in [`FootTracker::failed`] and leaves the
    /// last good assessment in place.
    pub fn touchdown(&mut self, leg: Leg, position: Point3<f64>) -> Result<Option<Assessment>, TerrainError> {
        if let Err(e) = check_point(|| format!("foot {leg}"), position.x, position.y, position.z) {
            self.rejected += 1;
            return Err(e);
        }
        self.feet[leg.index()] = Some(position);
        let Some(feet) = self.all_feet() else {
            return Ok(None);
        };
        match self.assessor.assess(&feet) {
            Ok(a) => {
                self.last = Some(a);
                Ok(Some(a))
            }
            Err(e) => {
                self.failed += 1;
                Err(e)
            }
        }
    }

    /// [`FootTracker::touchdown`] by the leg's name as the message carries it; an unknown name
    /// is refused and counted in [`FootTracker::rejected`].
    pub fn touchdown_named(&mut self, leg: &str, position: Point3<f64>) -> Result<Option<Assessment>, TerrainError> {
        match Leg::parse(leg) {
            Ok(leg) => self.touchdown(leg, position),
            Err(e) => {
                self.rejected += 1;
                Err(e)
            }
        }
    }

    /// The six latest touchdowns once every leg has touched down.
    pub fn all_feet(&self) -> Option<[Point3<f64>; 6]> {
        let mut out = [Point3::origin(); 6];
        for (o, f) in out.iter_mut().zip(&self.feet) {
            *o = (*f)?;
        }
        Some(out)
    }

    /// The latest touchdown of one leg.
    pub fn foot(&self, leg: Leg) -> Option<Point3<f64>> {
        self.feet[leg.index()]
    }

    /// The last good assessment.
    pub fn last(&self) -> Option<&Assessment> {
        self.last.as_ref()
    }

    /// Touchdowns refused: unknown leg, non-finite or out-of-range position.
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Touchdowns stored whose stance could not be assessed (a degenerate plane).
    pub fn failed(&self) -> u64 {
        self.failed
    }
}
