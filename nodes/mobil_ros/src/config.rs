//! A node's configuration, declared once.
//!
//! Each parameter is declared in exactly one place — name, type, default, range, description,
//! read-only — together with the field of the typed configuration it fills. From that one
//! declaration come the ROS parameter declarations, the `--help` table, the validation of every
//! start-up value and every `set_parameters` call (refused with a reason), the names and types
//! `describe_parameters` reports, and the typed configuration the node runs on.
//!
//! ```
//! use mobil_ros::config::{load, Config, ConfigError, Decl};
//! use mobil_ros::params::ParamValues;
//!
//! #[derive(Debug, Clone, Default, PartialEq)]
//! struct Teleop {
//!     speed: f64,
//!     limit: f64,
//!     frame: String,
//! }
//!
//! impl Config for Teleop {
//!     fn declare(d: &mut Decl<Self>) {
//!         d.double("speed", 0.2, "forward speed [m/s]", |c, v| c.speed = v).min(0.0);
//!         d.double("limit", 0.5, "speed limit [m/s]", |c, v| c.limit = v).above(0.0);
//!         d.string("frame", "base_link", "command frame", |c, v| c.frame = v).read_only();
//!     }
//!
//!     fn validate(&self) -> Result<(), ConfigError> {
//!         if self.speed > self.limit {
//!             return Err(ConfigError::inconsistent(format!("speed {} above limit {}", self.speed, self.limit)));
//!         }
//!         Ok(())
//!     }
//! }
//!
//! let defaults = ParamValues::defaults(&Decl::<Teleop>::of().specs());
//! let teleop: Teleop = load(&defaults).unwrap();
//! assert_eq!((teleop.speed, teleop.frame.as_str()), (0.2, "base_link"));
//! let mut too_fast = defaults.clone();
//! too_fast.set("speed", ros2_client::ParameterValue::Double(0.8));
//! assert!(load::<Teleop>(&too_fast).unwrap_err().to_string().contains("above limit"));
//! ```
//!
//! A node then runs on it with [`crate::NodeDecl::for_config`], [`crate::RosNode::config`] and
//! [`crate::RosNode::config_changed`]. Shared groups (the chassis geometry every node that
//! models the chassis declares) are declared once too, and nested with [`Decl::nest`].

use crate::params::{type_name, ParamSpec, ParamValues};
use ros2_client::ParameterValue;
use std::sync::Arc;
use thiserror::Error;

/// Declares parameters on a [`Decl`] as a table, a row per parameter: its kind (the [`Decl`]
/// method: `double`, `integer`, `boolean`, `string`, `parsed`, `doubles`, `double_list`), name,
/// default, the field it fills, any bounds ([`Declared`]'s methods), and its description:
///
/// ```
/// use mobil_ros::config::{load, Config, Decl};
/// use mobil_ros::params::ParamValues;
///
/// #[derive(Debug, Clone, Default)]
/// struct Limits { v_max: f64 }
/// #[derive(Debug, Clone, Default)]
/// struct Teleop { speed: f64, limits: Limits, frame: String, retries: usize }
///
/// impl Config for Teleop {
///     fn declare(d: &mut Decl<Self>) {
///         mobil_ros::params! { d;
///             double "speed" = 0.2 => speed, min(0.0); "forward speed [m/s]";
///             double "v_max" = 0.5 => limits.v_max, within(0.1, 2.0); "speed limit [m/s]";
///             count "retries" = 3usize => retries, within(0.0, 10.0); "attempts after the first";
///             string "frame" = "base_link" => frame, read_only(); "command frame";
///         }
///     }
/// }
///
/// let teleop: Teleop = load(&ParamValues::defaults(&Decl::<Teleop>::of().specs())).unwrap();
/// assert_eq!((teleop.speed, teleop.limits.v_max, teleop.frame.as_str()), (0.2, 0.5, "base_link"));
/// assert_eq!(teleop.retries, 3);
/// ```
///
/// Each row is the method call `d.KIND(NAME, DEFAULT, DESCRIPTION, |c, v| c.FIELD = v)` (KIND
/// one of `double`, `integer`, `count`, `boolean`, `string`, `parsed`, `double_list`, …) with
/// its bounds chained; a parameter whose value fills more than one field, or is converted, is
/// declared with the method itself.
#[macro_export]
macro_rules! params {
    ($d:ident; $(
        $kind:ident $name:literal = $default:expr => $($field:ident).+ $(, $bound:ident($($arg:expr),*))*; $doc:expr;
    )*) => {
        $( $d.$kind($name, $default, $doc, |c, v| c.$($field).+ = v)$(.$bound($($arg),*))*; )*
    };
}

/// Why parameter values do not make a configuration.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ConfigError {
    /// A value has the wrong type or is not declared (only possible when values and declaration
    /// disagree: the parameter services check types first).
    #[error("parameter `{name}`: {reason}")]
    Invalid {
        /// The parameter.
        name: String,
        /// Why.
        reason: String,
    },
    /// The values are fine alone but not together (e.g. a minimum above a maximum).
    #[error("{0}")]
    Inconsistent(String),
    /// The declaration names a parameter twice (a programming error, reported at start-up).
    #[error("parameter `{0}` is declared twice")]
    Duplicate(String),
}

impl ConfigError {
    /// An [`ConfigError::Inconsistent`] from any error or text (a library's validation error).
    pub fn inconsistent(reason: impl std::fmt::Display) -> Self {
        ConfigError::Inconsistent(reason.to_string())
    }
}

/// A typed configuration filled from parameters.
pub trait Config: Default + Clone + Send + Sync + 'static {
    /// Declares every parameter, once, with the field it fills.
    fn declare(d: &mut Decl<Self>);

    /// Checks the filled configuration as a whole (ranges of single values are in the
    /// declaration); a failure refuses the start-up or the parameter change with its reason.
    fn validate(&self) -> Result<(), ConfigError> {
        Ok(())
    }
}

type Setter<C> = Arc<dyn Fn(&mut C, &ParameterValue) -> Result<(), String> + Send + Sync>;

struct Entry<C> {
    spec: ParamSpec,
    set: Setter<C>,
}

/// The parameter declarations of a configuration `C`: each a [`ParamSpec`] and the setter of the
/// field it fills.
pub struct Decl<C> {
    entries: Vec<Entry<C>>,
    duplicates: Vec<String>,
}

/// The declaration just made, to add a range, choices or read-only.
pub struct Declared<'a>(&'a mut ParamSpec);

impl Declared<'_> {
    fn map(self, f: impl FnOnce(ParamSpec) -> ParamSpec) -> Self {
        let spec = std::mem::replace(self.0, ParamSpec::boolean("", false, ""));
        *self.0 = f(spec);
        self
    }

    /// Accept only values ≥ `min`.
    pub fn min(self, min: f64) -> Self {
        self.map(|s| s.min(min))
    }

    /// Accept only values > `min`.
    pub fn above(self, min: f64) -> Self {
        self.map(|s| s.above(min))
    }

    /// Accept only values ≤ `max`.
    pub fn max(self, max: f64) -> Self {
        self.map(|s| s.max(max))
    }

    /// Accept only values in [min, max].
    pub fn within(self, min: f64, max: f64) -> Self {
        self.map(|s| s.within(min, max))
    }

    /// Accept only one of these strings.
    pub fn choices(self, choices: &[&str]) -> Self {
        self.map(|s| s.choices(choices))
    }

    /// Accept only arrays of this length.
    pub fn length(self, n: usize) -> Self {
        self.map(|s| s.length(n))
    }

    /// Refuse changes after start-up (restart the node to change it).
    pub fn read_only(self) -> Self {
        self.map(ParamSpec::read_only)
    }
}

fn wrong_type(want: &str, got: &ParameterValue) -> String {
    format!("expected {want}, got {}", type_name(got))
}

impl<C: 'static> Decl<C> {
    fn empty() -> Self {
        Decl {
            entries: Vec::new(),
            duplicates: Vec::new(),
        }
    }

    fn push(&mut self, spec: ParamSpec, set: Setter<C>) -> Declared<'_> {
        if self.entries.iter().any(|e| e.spec.name == spec.name) {
            self.duplicates.push(spec.name.clone());
        }
        self.entries.push(Entry { spec, set });
        let last = self.entries.len() - 1;
        Declared(&mut self.entries[last].spec)
    }

    /// A floating-point parameter filling a field.
    pub fn double(
        &mut self,
        name: &str,
        default: f64,
        description: &str,
        set: impl Fn(&mut C, f64) + Send + Sync + 'static,
    ) -> Declared<'_> {
        self.push(
            ParamSpec::double(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::Double(d) => {
                    set(c, *d);
                    Ok(())
                }
                other => Err(wrong_type("double", other)),
            }),
        )
    }

    /// An integer parameter filling a field.
    pub fn integer(
        &mut self,
        name: &str,
        default: i64,
        description: &str,
        set: impl Fn(&mut C, i64) + Send + Sync + 'static,
    ) -> Declared<'_> {
        self.push(
            ParamSpec::integer(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::Integer(i) => {
                    set(c, *i);
                    Ok(())
                }
                other => Err(wrong_type("integer", other)),
            }),
        )
    }

    /// An integer parameter filling a field of an integer type `T` (`usize`, `u32`, `u8`, …): a
    /// count or an index. Its bounds should keep it within `T`; a value `T` cannot hold is
    /// refused (never wrapped, never read as 0) with the range `T` takes.
    pub fn count<T>(
        &mut self,
        name: &str,
        default: T,
        description: &str,
        set: impl Fn(&mut C, T) + Send + Sync + 'static,
    ) -> Declared<'_>
    where
        T: TryFrom<i64> + TryInto<i64> + Copy + Send + Sync + 'static,
    {
        let default = default.try_into().unwrap_or(i64::MAX);
        let type_name = std::any::type_name::<T>();
        self.push(
            ParamSpec::integer(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::Integer(i) => {
                    let value = T::try_from(*i).map_err(|_| format!("{i} does not fit a {type_name}"))?;
                    set(c, value);
                    Ok(())
                }
                other => Err(wrong_type("integer", other)),
            }),
        )
    }

    /// A boolean parameter filling a field.
    pub fn boolean(
        &mut self,
        name: &str,
        default: bool,
        description: &str,
        set: impl Fn(&mut C, bool) + Send + Sync + 'static,
    ) -> Declared<'_> {
        self.push(
            ParamSpec::boolean(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::Boolean(b) => {
                    set(c, *b);
                    Ok(())
                }
                other => Err(wrong_type("bool", other)),
            }),
        )
    }

    /// A string parameter filling a field.
    pub fn string(
        &mut self,
        name: &str,
        default: &str,
        description: &str,
        set: impl Fn(&mut C, String) + Send + Sync + 'static,
    ) -> Declared<'_> {
        self.push(
            ParamSpec::string(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::String(s) => {
                    set(c, s.clone());
                    Ok(())
                }
                other => Err(wrong_type("string", other)),
            }),
        )
    }

    /// A string parameter parsed into a field of type `T` (an enum by name, with its names as
    /// `choices`); a value that does not parse is refused with the parser's reason.
    pub fn parsed<T>(
        &mut self,
        name: &str,
        default: &str,
        description: &str,
        set: impl Fn(&mut C, T) + Send + Sync + 'static,
    ) -> Declared<'_>
    where
        T: std::str::FromStr,
        T::Err: std::fmt::Display,
    {
        self.push(
            ParamSpec::string(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::String(s) => {
                    set(c, s.parse::<T>().map_err(|e| e.to_string())?);
                    Ok(())
                }
                other => Err(wrong_type("string", other)),
            }),
        )
    }

    /// A fixed-length array of doubles filling a field (`[x, y, yaw]`, covariances): the length
    /// is part of the declaration.
    pub fn doubles<const N: usize>(
        &mut self,
        name: &str,
        default: [f64; N],
        description: &str,
        set: impl Fn(&mut C, [f64; N]) + Send + Sync + 'static,
    ) -> Declared<'_> {
        self.push(
            ParamSpec::doubles(name, &default, description).length(N),
            Arc::new(move |c, v| match v {
                ParameterValue::DoubleArray(a) => {
                    let array: [f64; N] = a
                        .as_slice()
                        .try_into()
                        .map_err(|_| format!("expected {N} elements, got {}", a.len()))?;
                    set(c, array);
                    Ok(())
                }
                other => Err(wrong_type("double array", other)),
            }),
        )
    }

    /// An array of doubles of any length filling a field (a weight profile whose length follows
    /// another parameter; [`Config::validate`] checks the length).
    pub fn double_list(
        &mut self,
        name: &str,
        default: &[f64],
        description: &str,
        set: impl Fn(&mut C, Vec<f64>) + Send + Sync + 'static,
    ) -> Declared<'_> {
        self.push(
            ParamSpec::doubles(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::DoubleArray(a) => {
                    set(c, a.clone());
                    Ok(())
                }
                other => Err(wrong_type("double array", other)),
            }),
        )
    }

    /// An array of strings filling a field (names of instances, as Nav2's `docks`).
    pub fn strings(
        &mut self,
        name: &str,
        default: &[&str],
        description: &str,
        set: impl Fn(&mut C, Vec<String>) + Send + Sync + 'static,
    ) -> Declared<'_> {
        self.push(
            ParamSpec::strings(name, default, description),
            Arc::new(move |c, v| match v {
                ParameterValue::StringArray(a) => {
                    set(c, a.clone());
                    Ok(())
                }
                other => Err(wrong_type("string array", other)),
            }),
        )
    }

    /// Declares a group of parameters (its own [`Decl`]) that fills one part of `C`, e.g. the
    /// chassis geometry shared by every node that models the chassis.
    pub fn nest<S: 'static>(
        &mut self,
        part: impl Fn(&mut C) -> &mut S + Send + Sync + Clone + 'static,
        declare: impl FnOnce(&mut Decl<S>),
    ) {
        let mut inner = Decl::<S>::empty();
        declare(&mut inner);
        self.duplicates.extend(inner.duplicates);
        for Entry { spec, set } in inner.entries {
            let part = part.clone();
            self.push(spec, Arc::new(move |c, v| set(part(c), v)));
        }
    }

    /// Every declared parameter, in declaration order.
    pub fn specs(&self) -> Vec<ParamSpec> {
        self.entries.iter().map(|e| e.spec.clone()).collect()
    }
}

impl<C: Config> Decl<C> {
    /// The declaration of `C`.
    pub fn of() -> Self {
        let mut d = Decl::empty();
        C::declare(&mut d);
        d
    }

    /// The configuration from parameter values: every declared field set, then validated.
    pub fn build(&self, values: &ParamValues) -> Result<C, ConfigError> {
        if let Some(name) = self.duplicates.first() {
            return Err(ConfigError::Duplicate(name.clone()));
        }
        let mut config = C::default();
        for e in &self.entries {
            let name = &e.spec.name;
            let value = values.get(name).ok_or_else(|| ConfigError::Invalid {
                name: name.clone(),
                reason: "no value".into(),
            })?;
            (e.set)(&mut config, value).map_err(|reason| ConfigError::Invalid {
                name: name.clone(),
                reason,
            })?;
        }
        config.validate()?;
        Ok(config)
    }
}

/// The configuration `C` from parameter values (see [`Decl::build`]).
pub fn load<C: Config>(values: &ParamValues) -> Result<C, ConfigError> {
    Decl::<C>::of().build(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, Default, PartialEq)]
    struct Geometry {
        radius: f64,
        wheels: i64,
    }

    #[derive(Debug, Clone, Default, PartialEq)]
    struct Node {
        geometry: Geometry,
        rate: f64,
        mount: [f64; 3],
        enabled: bool,
    }

    fn geometry(d: &mut Decl<Geometry>) {
        d.double("radius", 0.1, "wheel radius [m]", |c, v| c.radius = v)
            .above(0.0);
        d.integer("wheels", 4, "wheels", |c, v| c.wheels = v).within(3.0, 4.0);
    }

    impl Config for Node {
        fn declare(d: &mut Decl<Self>) {
            d.nest(|c: &mut Node| &mut c.geometry, geometry);
            d.double("rate", 50.0, "rate [Hz]", |c, v| c.rate = v)
                .within(1.0, 100.0);
            d.doubles("mount", [0.3, 0.0, 0.0], "x, y, yaw", |c, v| c.mount = v);
            d.boolean("enabled", true, "on", |c, v| c.enabled = v).read_only();
        }

        fn validate(&self) -> Result<(), ConfigError> {
            // A made-up rule across the nested group and the node's own parameters.
            if self.geometry.wheels == 3 && self.rate > 60.0 {
                return Err(ConfigError::inconsistent("three wheels need rate ≤ 60 Hz"));
            }
            Ok(())
        }
    }

    #[test]
    fn a_count_fills_its_type_and_refuses_what_it_cannot_hold() {
        #[derive(Debug, Clone, Default)]
        struct Counts {
            beams: usize,
            level: u8,
        }
        impl Config for Counts {
            fn declare(d: &mut Decl<Self>) {
                d.count("beams", 360usize, "beams", |c, v| c.beams = v);
                d.count("level", 2u8, "level", |c, v| c.level = v);
            }
        }
        let d = Decl::<Counts>::of();
        let mut values = ParamValues::defaults(&d.specs());
        let c = d.build(&values).expect("defaults");
        assert_eq!((c.beams, c.level), (360, 2));
        values.set("level", ParameterValue::Integer(300));
        let e = d.build(&values).expect_err("300 is no u8");
        assert_eq!(e.to_string(), "parameter `level`: 300 does not fit a u8");
        values.set("level", ParameterValue::Integer(3));
        values.set("beams", ParameterValue::Integer(-1));
        assert!(d
            .build(&values)
            .expect_err("no negative count")
            .to_string()
            .contains("-1 does not fit a usize"));
    }

    #[test]
    fn one_declaration_gives_specs_defaults_and_typed_values() {
        let specs = Decl::<Node>::of().specs();
        let names: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["radius", "wheels", "rate", "mount", "enabled"]);
        assert!(specs[4].read_only && !specs[2].read_only);
        // The range came with the declaration: 0.5 Hz is refused by the spec, with a reason.
        let e = specs[2].check(&ParameterValue::Double(0.5)).unwrap_err();
        assert!(e.contains("below the minimum"), "{e}");
        assert!(specs[3].check(&ParameterValue::DoubleArray(vec![1.0])).is_err());

        let mut values = ParamValues::defaults(&specs);
        assert_eq!(
            load::<Node>(&values).unwrap(),
            Node {
                geometry: Geometry { radius: 0.1, wheels: 4 },
                rate: 50.0,
                mount: [0.3, 0.0, 0.0],
                enabled: true
            }
        );
        values.set("radius", ParameterValue::Double(0.25));
        values.set("mount", ParameterValue::DoubleArray(vec![1.0, 2.0, 3.0]));
        let node = load::<Node>(&values).unwrap();
        assert_eq!((node.geometry.radius, node.mount), (0.25, [1.0, 2.0, 3.0]));
    }

    #[test]
    fn inconsistent_and_mistyped_values_are_typed_errors() {
        let mut values = ParamValues::defaults(&Decl::<Node>::of().specs());
        values.set("wheels", ParameterValue::Integer(3));
        values.set("rate", ParameterValue::Double(80.0));
        assert_eq!(
            load::<Node>(&values),
            Err(ConfigError::Inconsistent("three wheels need rate ≤ 60 Hz".into()))
        );
        values.set("rate", ParameterValue::String("fast".into()));
        assert_eq!(
            load::<Node>(&values),
            Err(ConfigError::Invalid {
                name: "rate".into(),
                reason: "expected double, got string".into()
            })
        );
    }

    #[derive(Debug, Clone, Default, PartialEq)]
    struct Mode(u8);

    impl Config for Mode {
        fn declare(d: &mut Decl<Self>) {
            d.parsed("mode", "2", "a number as text", |c, v: u8| c.0 = v);
        }
    }

    #[test]
    fn parsed_strings_fill_typed_fields_or_give_the_reason() {
        let mut values = ParamValues::defaults(&Decl::<Mode>::of().specs());
        assert_eq!(load::<Mode>(&values), Ok(Mode(2)));
        values.set("mode", ParameterValue::String("300".into()));
        assert_eq!(
            load::<Mode>(&values),
            Err(ConfigError::Invalid {
                name: "mode".into(),
                reason: "number too large to fit in target type".into()
            })
        );
    }

    #[derive(Debug, Clone, Default)]
    struct Twice(f64);

    impl Config for Twice {
        fn declare(d: &mut Decl<Self>) {
            d.double("x", 1.0, "x", |c, v| c.0 = v);
            d.double("x", 2.0, "x again", |c, v| c.0 = v);
        }
    }

    #[test]
    fn a_name_declared_twice_is_refused() {
        let d = Decl::<Twice>::of();
        let values = ParamValues::defaults(&d.specs());
        assert_eq!(d.build(&values).unwrap_err(), ConfigError::Duplicate("x".into()));
    }
}
