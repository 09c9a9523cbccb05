//! A dock database in opennav_docking's form: named dock instances, each with a `type`, a
//! `frame`, a `pose` `[x, y, yaw]` and an optional `id`, for `DockRobot` goals that name a dock
//! (`use_dock_id`, `dock_id` = the instance's name).
//!
//! The node reads the instances from its parameters (`docks: [name, …]` and `name.type`,
//! `name.frame`, `name.pose`, `name.id`) or from a `dock_database` YAML file; this module checks
//! them and answers the look-ups, with DockRobot's code DOCK_NOT_IN_DB for an unknown name. A
//! dock's frame is the node's to place through tf (a dock in `map` needs `map → odom`).
//!
//! ```
//! use mobil_planner::docks::{DockDatabase, DockFields};
//! let db = DockDatabase::new(vec![(
//!     "home".to_owned(),
//!     DockFields { pose: Some(vec![1.0, 0.5, 0.0]), frame: Some("odom".into()), ..Default::default() },
//! )])
//! .unwrap();
//! let home = db.get("home").unwrap();
//! assert_eq!((home.pose.x, home.frame.as_str()), (1.0, "odom"));
//! assert_eq!(db.get("away").unwrap_err().nav2_error(), 901);
//! ```

use mobil_geom::Pose2;
use mobil_motion::{nav2, Outcome};
use thiserror::Error;

/// The frame a dock without one is in (opennav_docking's default).
pub const DEFAULT_FRAME: &str = "map";

/// One dock instance as given: each field may be missing.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DockFields {
    /// The dock plugin's type (kept, and logged: the planner has one docking law).
    pub dock_type: Option<String>,
    /// The pose's frame (default `map`).
    pub frame: Option<String>,
    /// `[x, y, yaw]`.
    pub pose: Option<Vec<f64>>,
    /// An identifier for the dock's detection (kept, not used).
    pub id: Option<String>,
}

/// A checked dock.
#[derive(Debug, Clone, PartialEq)]
pub struct Dock {
    /// The instance's name: what `dock_id` names.
    pub name: String,
    /// The type as given (empty if none).
    pub dock_type: String,
    /// The pose's frame.
    pub frame: String,
    /// The dock pose.
    pub pose: Pose2,
    /// The identifier as given (empty if none).
    pub id: String,
}

/// Why a database cannot be built.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DockError {
    /// A dock without a pose.
    #[error("dock `{0}` has no pose: give `{0}.pose: [x, y, yaw]`")]
    NoPose(String),
    /// A pose that is not three finite numbers.
    #[error("dock `{0}`: pose must be three finite numbers [x, y, yaw]")]
    BadPose(String),
    /// A name given twice.
    #[error("dock `{0}` is given twice")]
    Duplicate(String),
    /// An empty name.
    #[error("a dock name is empty")]
    EmptyName,
}

/// The docks, by name.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DockDatabase {
    docks: Vec<Dock>,
}

impl DockDatabase {
    /// Checks the instances (in order): every one needs a pose of three finite numbers; a
    /// missing frame is `map`.
    pub fn new(instances: Vec<(String, DockFields)>) -> Result<Self, DockError> {
        let mut docks: Vec<Dock> = Vec::with_capacity(instances.len());
        for (name, f) in instances {
            if name.is_empty() {
                return Err(DockError::EmptyName);
            }
            if docks.iter().any(|d| d.name == name) {
                return Err(DockError::Duplicate(name));
            }
            let pose = f.pose.ok_or_else(|| DockError::NoPose(name.clone()))?;
            let pose = Pose2::from_values(&pose).ok_or_else(|| DockError::BadPose(name.clone()))?;
            docks.push(Dock {
                dock_type: f.dock_type.unwrap_or_default(),
                frame: f.frame.unwrap_or_else(|| DEFAULT_FRAME.to_owned()),
                id: f.id.unwrap_or_default(),
                pose,
                name,
            });
        }
        Ok(DockDatabase { docks })
    }

    /// The docks.
    pub fn docks(&self) -> &[Dock] {
        &self.docks
    }

    /// The dock named `name`, or DOCK_NOT_IN_DB.
    pub fn get(&self, name: &str) -> Result<&Dock, Outcome> {
        self.docks.iter().find(|d| d.name == name).ok_or_else(|| {
            let known: Vec<&str> = self.docks.iter().map(|d| d.name.as_str()).collect();
            Outcome::failed(
                "INVALID_GOAL",
                format!(
                    "dock_id `{name}` is not in the dock database ({})",
                    if known.is_empty() {
                        "which is empty: set docks or dock_database".to_owned()
                    } else {
                        format!("docks: {}", known.join(", "))
                    }
                ),
                nav2::docking::DOCK_NOT_IN_DB,
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fields(pose: &[f64], frame: Option<&str>) -> DockFields {
        DockFields {
            dock_type: Some("charging_dock".into()),
            frame: frame.map(str::to_owned),
            pose: Some(pose.to_vec()),
            id: None,
        }
    }

    #[test]
    fn docks_are_checked_and_found_by_name() {
        let db = DockDatabase::new(vec![
            ("dock1".into(), fields(&[1.0, 2.0, 0.5], Some("odom"))),
            ("dock2".into(), fields(&[-1.0, 0.0, 3.0], None)),
        ])
        .unwrap();
        assert_eq!(db.get("dock1").unwrap().pose, Pose2::new(1.0, 2.0, 0.5));
        assert_eq!(db.docks()[1].frame, "map");
        let unknown = db.get("dock3").unwrap_err();
        assert_eq!(unknown.nav2_error(), 901);
        assert!(unknown.reason().contains("docks: dock1, dock2"), "{}", unknown.reason());
        let empty = DockDatabase::default().get("x").unwrap_err();
        assert!(empty.reason().contains("empty"));
    }

    #[test]
    fn bad_instances_are_refused() {
        let no_pose = DockFields::default();
        assert_eq!(
            DockDatabase::new(vec![("a".into(), no_pose)]),
            Err(DockError::NoPose("a".into()))
        );
        assert_eq!(
            DockDatabase::new(vec![("a".into(), fields(&[1.0, f64::NAN, 0.0], None))]),
            Err(DockError::BadPose("a".into()))
        );
        assert_eq!(
            DockDatabase::new(vec![("a".into(), fields(&[1.0, 0.0], None))]),
            Err(DockError::BadPose("a".into()))
        );
        let twice = vec![
            ("a".into(), fields(&[0.0, 0.0, 0.0], None)),
            ("a".into(), fields(&[1.0, 0.0, 0.0], None)),
        ];
        assert_eq!(DockDatabase::new(twice), Err(DockError::Duplicate("a".into())));
        assert_eq!(
            DockDatabase::new(vec![(String::new(), fields(&[0.0, 0.0, 0.0], None))]),
            Err(DockError::EmptyName)
        );
    }
}
