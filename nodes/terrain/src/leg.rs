//! The six legs by the paper's names (001, Fig. 1), in the order of `TerrainAssessment.feet`.

use crate::error::TerrainError;
use std::fmt;
use std::str::FromStr;

/// One leg of the hexapod. K = kairė (left), D = dešinė (right); P = priekinė (front),
/// V = vidurinė (middle), G = galinė (rear).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Leg {
    /// Left front.
    KP,
    /// Left middle.
    KV,
    /// Left rear.
    KG,
    /// Right front.
    DP,
    /// Right middle.
    DV,
    /// Right rear.
    DG,
}

/// The two tripods of the tripod gait. Tripod A carries plane 1, tripod B plane 2 (SPEC §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Tripod {
    /// KP, KG, DV: the feet of plane 1.
    A,
    /// DP, DG, KV: the feet of plane 2.
    B,
}

impl Leg {
    /// Every leg, in the message's order (KP, KV, KG, DP, DV, DG); [`Leg::index`] is the position here.
    pub const ALL: [Leg; 6] = [Leg::KP, Leg::KV, Leg::KG, Leg::DP, Leg::DV, Leg::DG];

    /// Feet of plane 1, in the paper's vertex order (KP, KG, DV).
    pub const PLANE1: [Leg; 3] = [Leg::KP, Leg::KG, Leg::DV];

    /// Feet of plane 2, in the paper's vertex order (DP, DG, KV).
    pub const PLANE2: [Leg; 3] = [Leg::DP, Leg::DG, Leg::KV];

    /// Position of the leg in [`Leg::ALL`] and in `TerrainAssessment.feet`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The leg's name as in the message (`"KP"`, …).
    pub fn name(self) -> &'static str {
        match self {
            Leg::KP => "KP",
            Leg::KV => "KV",
            Leg::KG => "KG",
            Leg::DP => "DP",
            Leg::DV => "DV",
            Leg::DG => "DG",
        }
    }

    /// Parses a leg name exactly as the message spells it (upper case); anything else is
    /// [`TerrainError::UnknownLeg`].
    pub fn parse(name: &str) -> Result<Leg, TerrainError> {
        Leg::ALL
            .into_iter()
            .find(|leg| leg.name() == name)
            .ok_or_else(|| TerrainError::UnknownLeg(name.to_owned()))
    }

    /// True for the left legs (K…), which sit at y > 0 in the body frame (y left).
    pub fn is_left(self) -> bool {
        matches!(self, Leg::KP | Leg::KV | Leg::KG)
    }

    /// The same leg on the other side (KP ↔ DP, KV ↔ DV, KG ↔ DG).
    pub fn mirrored(self) -> Leg {
        match self {
            Leg::KP => Leg::DP,
            Leg::KV => Leg::DV,
            Leg::KG => Leg::DG,
            Leg::DP => Leg::KP,
            Leg::DV => Leg::KV,
            Leg::DG => Leg::KG,
        }
    }

    /// The tripod the leg belongs to in the tripod gait.
    pub fn tripod(self) -> Tripod {
        if Leg::PLANE1.contains(&self) {
            Tripod::A
        } else {
            Tripod::B
        }
    }
}

impl fmt::Display for Leg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Leg {
    type Err = TerrainError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Leg::parse(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_in_message_order() {
        let names: Vec<&str> = Leg::ALL.iter().map(|l| l.name()).collect();
        assert_eq!(names, ["KP", "KV", "KG", "DP", "DV", "DG"]);
        for (i, leg) in Leg::ALL.into_iter().enumerate() {
            assert_eq!(leg.index(), i);
            assert_eq!(Leg::parse(leg.name()), Ok(leg));
        }
    }

    #[test]
    fn unknown_names_are_refused() {
        for bad in ["", "kp", "KP ", "XX", "KPX"] {
            assert_eq!(Leg::parse(bad), Err(TerrainError::UnknownLeg(bad.to_owned())));
        }
    }

    #[test]
    fn tripods_and_mirrors() {
        assert_eq!(Leg::KP.tripod(), Tripod::A);
        assert_eq!(Leg::KG.tripod(), Tripod::A);
        assert_eq!(Leg::DV.tripod(), Tripod::A);
        assert_eq!(Leg::KV.tripod(), Tripod::B);
        assert_eq!(Leg::DP.tripod(), Tripod::B);
        assert_eq!(Leg::DG.tripod(), Tripod::B);
        for leg in Leg::ALL {
            assert_eq!(leg.mirrored().mirrored(), leg);
            assert_ne!(leg.is_left(), leg.mirrored().is_left());
        }
        // Mirroring maps the feet of plane 1 onto those of plane 2.
        let mut m: Vec<Leg> = Leg::PLANE1.iter().map(|l| l.mirrored()).collect();
        m.sort();
        let mut p2 = Leg::PLANE2.to_vec();
        p2.sort();
        assert_eq!(m, p2);
    }
}
