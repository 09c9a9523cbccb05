//! A parser for ROS 2 `.msg` / `.srv` files and the Rust code generator behind this crate.
//!
//! Used by `build.rs` (the same file is included there with `#[path]`) and unit-tested here.
//! An `.action` file becomes its three parts (`Name_Goal`, `Name_Result`, `Name_Feedback`) plus
//! a marker type implementing `crate::RosAction`, which names the action for ros2-client.
//! Supported: every primitive type, bounded and unbounded strings, fixed (`T[N]`), bounded
//! (`T[<=N]`) and unbounded (`T[]`) arrays, nested messages (same package or `pkg/Type`),
//! constants (`TYPE NAME=VALUE`) and default values (`TYPE name VALUE`). `wstring` is refused.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::fmt::{self, Write as _};

/// A primitive ROS type and its Rust counterpart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Primitive {
    Bool,
    Byte,
    Char,
    Float32,
    Float64,
    Int8,
    Uint8,
    Int16,
    Uint16,
    Int32,
    Uint32,
    Int64,
    Uint64,
}

impl Primitive {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "bool" => Self::Bool,
            "byte" => Self::Byte,
            "char" => Self::Char,
            "float32" => Self::Float32,
            "float64" => Self::Float64,
            "int8" => Self::Int8,
            "uint8" => Self::Uint8,
            "int16" => Self::Int16,
            "uint16" => Self::Uint16,
            "int32" => Self::Int32,
            "uint32" => Self::Uint32,
            "int64" => Self::Int64,
            "uint64" => Self::Uint64,
            _ => return None,
        })
    }

    /// The Rust type (`byte` and `char` are octets in ROS 2).
    pub fn rust(self) -> &'static str {
        match self {
            Self::Bool => "bool",
            Self::Byte | Self::Char | Self::Uint8 => "u8",
            Self::Float32 => "f32",
            Self::Float64 => "f64",
            Self::Int8 => "i8",
            Self::Int16 => "i16",
            Self::Uint16 => "u16",
            Self::Int32 => "i32",
            Self::Uint32 => "u32",
            Self::Int64 => "i64",
            Self::Uint64 => "u64",
        }
    }

    /// Renders a literal of this type, checking that it parses and fits.
    fn literal(self, value: &str) -> Result<String, String> {
        let v = value.trim();
        match self {
            Self::Bool => match v {
                "true" | "True" | "1" => Ok("true".into()),
                "false" | "False" | "0" => Ok("false".into()),
                _ => Err(format!("`{v}` is not a bool")),
            },
            Self::Float32 | Self::Float64 => {
                let f: f64 = v.parse().map_err(|_| format!("`{v}` is not a number"))?;
                if !f.is_finite() {
                    return Err(format!("`{v}` is not finite"));
                }
                Ok(format!("{f:?}"))
            }
            _ => {
                let i: i128 = v.parse().map_err(|_| format!("`{v}` is not an integer"))?;
                let (lo, hi): (i128, i128) = match self {
                    Self::Int8 => (i8::MIN.into(), i8::MAX.into()),
                    Self::Byte | Self::Char | Self::Uint8 => (0, u8::MAX.into()),
                    Self::Int16 => (i16::MIN.into(), i16::MAX.into()),
                    Self::Uint16 => (0, u16::MAX.into()),
                    Self::Int32 => (i32::MIN.into(), i32::MAX.into()),
                    Self::Uint32 => (0, u32::MAX.into()),
                    Self::Int64 => (i64::MIN.into(), i64::MAX.into()),
                    _ => (0, u64::MAX.into()),
                };
                if i < lo || i > hi {
                    return Err(format!("{i} does not fit in {}", self.rust()));
                }
                Ok(i.to_string())
            }
        }
    }
}

/// The element type of a field.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BaseType {
    Primitive(Primitive),
    /// `string` or `string<=N` (the bound is documentation on the Rust side).
    String {
        bound: Option<usize>,
    },
    /// A nested message, always with its package resolved.
    Message {
        package: String,
        name: String,
    },
}

/// How many elements a field holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArrayKind {
    Single,
    Fixed(usize),
    Bounded(usize),
    Unbounded,
}

/// A field's full type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldType {
    pub base: BaseType,
    pub array: ArrayKind,
}

/// One field of a message.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    pub name: String,
    pub ty: FieldType,
    pub default: Option<String>,
}

/// One constant of a message.
#[derive(Debug, Clone, PartialEq)]
pub struct Constant {
    pub name: String,
    pub ty: BaseType,
    pub value: String,
}

/// A parsed message definition.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MsgSpec {
    pub package: String,
    pub name: String,
    pub fields: Vec<Field>,
    pub constants: Vec<Constant>,
}

/// An error in a definition, with the 1-based line it was found on (0: the file as a whole).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IdlError {
    pub line: usize,
    pub message: String,
}

impl fmt::Display for IdlError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.message)
        } else {
            write!(f, "line {}: {}", self.line, self.message)
        }
    }
}

fn err(line: usize, message: impl Into<String>) -> IdlError {
    IdlError {
        line,
        message: message.into(),
    }
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c.is_ascii_alphabetic()) && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

fn parse_type(package: &str, text: &str, line: usize) -> Result<FieldType, IdlError> {
    let (base_text, array) = match text.find('[') {
        None => (text, ArrayKind::Single),
        Some(open) => {
            let inner = text[open + 1..]
                .strip_suffix(']')
                .ok_or_else(|| err(line, format!("unclosed array bracket in `{text}`")))?;
            let array = if inner.is_empty() {
                ArrayKind::Unbounded
            } else if let Some(bound) = inner.strip_prefix("<=") {
                ArrayKind::Bounded(
                    bound
                        .parse()
                        .map_err(|_| err(line, format!("bad array bound `{inner}`")))?,
                )
            } else {
                ArrayKind::Fixed(
                    inner
                        .parse()
                        .map_err(|_| err(line, format!("bad array size `{inner}`")))?,
                )
            };
            (&text[..open], array)
        }
    };
    let base = if let Some(p) = Primitive::parse(base_text) {
        BaseType::Primitive(p)
    } else if base_text == "string" {
        BaseType::String { bound: None }
    } else if let Some(bound) = base_text.strip_prefix("string<=") {
        BaseType::String {
            bound: Some(
                bound
                    .parse()
                    .map_err(|_| err(line, format!("bad string bound `{base_text}`")))?,
            ),
        }
    } else if base_text.starts_with("wstring") {
        return Err(err(line, "wstring is not supported"));
    } else {
        let parts: Vec<&str> = base_text.split('/').collect();
        let (pkg, name) = match parts.as_slice() {
            [name] => (package, *name),
            [pkg, name] | [pkg, "msg", name] => (*pkg, *name),
            _ => return Err(err(line, format!("bad type `{base_text}`"))),
        };
        if !is_identifier(pkg) || !is_identifier(name) {
            return Err(err(line, format!("bad type `{base_text}`")));
        }
        BaseType::Message {
            package: pkg.to_owned(),
            name: name.to_owned(),
        }
    };
    Ok(FieldType { base, array })
}

/// Parses one `.msg` body (or one half of a `.srv`).
pub fn parse_msg(package: &str, name: &str, text: &str) -> Result<MsgSpec, IdlError> {
    let mut spec = MsgSpec {
        package: package.to_owned(),
        name: name.to_owned(),
        ..Default::default()
    };
    for (index, raw) in text.lines().enumerate() {
        let line_no = index + 1;
        let trimmed = raw.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let (type_text, rest) = trimmed
            .split_once(char::is_whitespace)
            .ok_or_else(|| err(line_no, format!("expected `TYPE NAME`, found `{trimmed}`")))?;
        let rest = rest.trim_start();
        let ty = parse_type(package, type_text, line_no)?;
        // Constants: `TYPE NAME=VALUE`; a string constant's value runs to the end of the line.
        let name_end = rest.find(|c: char| c.is_whitespace() || c == '=').unwrap_or(rest.len());
        let field_name = &rest[..name_end];
        let after = rest[name_end..].trim_start();
        if !is_identifier(field_name) {
            return Err(err(line_no, format!("bad name `{field_name}`")));
        }
        if let Some(value) = after.strip_prefix('=') {
            if ty.array != ArrayKind::Single || matches!(ty.base, BaseType::Message { .. }) {
                return Err(err(line_no, "constants must be of a primitive or string type"));
            }
            let value = match ty.base {
                BaseType::String { .. } => unquote(value.trim()),
                _ => strip_comment(value).trim().to_owned(),
            };
            spec.constants.push(Constant {
                name: field_name.to_owned(),
                ty: ty.base,
                value,
            });
        } else {
            let default = strip_comment(after).trim();
            if spec.fields.iter().any(|f| f.name == field_name) {
                return Err(err(line_no, format!("duplicate field `{field_name}`")));
            }
            spec.fields.push(Field {
                name: field_name.to_owned(),
                ty,
                default: (!default.is_empty()).then(|| default.to_owned()),
            });
        }
    }
    Ok(spec)
}

/// Removes a trailing `# comment`, leaving `#` inside quotes alone.
fn strip_comment(s: &str) -> &str {
    let mut quote: Option<char> = None;
    for (i, c) in s.char_indices() {
        match (quote, c) {
            (None, '#') => return &s[..i],
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            _ => {}
        }
    }
    s
}

fn unquote(s: &str) -> String {
    let bytes = s.as_bytes();
    if bytes.len() >= 2 && (bytes[0] == b'"' || bytes[0] == b'\'') && bytes[bytes.len() - 1] == bytes[0] {
        s[1..s.len() - 1].to_owned()
    } else {
        s.to_owned()
    }
}

/// Splits a definition at its `---` lines.
fn split_parts(text: &str) -> Vec<&str> {
    let mut parts = Vec::new();
    let (mut start, mut offset) = (0, 0);
    for line in text.split_inclusive('\n') {
        if line.trim() == "---" {
            parts.push(&text[start..offset]);
            start = offset + line.len();
        }
        offset += line.len();
    }
    parts.push(&text[start..]);
    parts
}

/// Splits a `.srv` into its request and response halves.
pub fn split_srv(text: &str) -> Result<(&str, &str), IdlError> {
    match split_parts(text).as_slice() {
        [request, response] => Ok((request, response)),
        _ => Err(err(0, "a service needs one `---` line between request and response")),
    }
}

/// Splits an `.action` into its goal, result and feedback parts.
pub fn split_action(text: &str) -> Result<(&str, &str, &str), IdlError> {
    match split_parts(text).as_slice() {
        [goal, result, feedback] => Ok((goal, result, feedback)),
        _ => Err(err(0, "an action needs two `---` lines: goal, result, feedback")),
    }
}

#[derive(Debug, Default)]
struct Package {
    msgs: Vec<MsgSpec>,
    /// Service name → (request, response), both also in `msgs` of the `srv` module.
    srvs: Vec<(String, MsgSpec, MsgSpec)>,
    /// Action name → (goal, result, feedback), in the `action` module.
    actions: Vec<(String, MsgSpec, MsgSpec, MsgSpec)>,
}

/// All definitions to generate, grouped by package.
#[derive(Debug, Default)]
pub struct Packages {
    packages: BTreeMap<String, Package>,
}

const RUST_KEYWORDS: &[&str] = &[
    "as", "async", "await", "break", "const", "continue", "crate", "dyn", "else", "enum", "extern", "false", "fn",
    "for", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return", "self", "static",
    "struct", "super", "trait", "true", "type", "unsafe", "use", "where", "while", "abstract", "become", "box", "do",
    "final", "macro", "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "gen",
];

fn rust_field_name(name: &str) -> String {
    if RUST_KEYWORDS.contains(&name) {
        format!("r#{name}")
    } else {
        name.to_owned()
    }
}

/// Type ids of `type_description_interfaces/msg/FieldType` (REP-2011), as rosidl gives them.
mod type_id {
    pub const NESTED_TYPE: u8 = 1;
    pub const STRING: u8 = 17;
    pub const BOUNDED_STRING: u8 = 21;
    pub const ARRAY_OFFSET: u8 = 48;
    pub const BOUNDED_SEQUENCE_OFFSET: u8 = 96;
    pub const UNBOUNDED_SEQUENCE_OFFSET: u8 = 144;
}

impl Primitive {
    /// The `FIELD_TYPE_*` id: `char` is `uint8` and `byte` `octet` in the .msg → IDL mapping.
    fn type_id(self) -> u8 {
        match self {
            Self::Int8 => 2,
            Self::Uint8 | Self::Char => 3,
            Self::Int16 => 4,
            Self::Uint16 => 5,
            Self::Int32 => 6,
            Self::Uint32 => 7,
            Self::Int64 => 8,
            Self::Uint64 => 9,
            Self::Float32 => 10,
            Self::Float64 => 11,
            Self::Bool => 15,
            Self::Byte => 16,
        }
    }
}

/// `"…"` with Python's `json.dumps` escapes (type and field names are ASCII identifiers).
fn json_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 || !c.is_ascii() => {
                let mut buf = [0u16; 2];
                for unit in c.encode_utf16(&mut buf) {
                    let _ = write!(out, "\\u{unit:04x}");
                }
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

impl MsgSpec {
    /// `pkg/<kind>/Name` of the type: `msg`, `srv` (`Name_Request`, `Name_Response`) or
    /// `action` (`Name_Goal`, …).
    fn type_name(&self, kind: &str) -> String {
        format!("{}/{kind}/{}", self.package, self.name)
    }

    /// The individual type description in the hashable form of REP-2011 (field defaults left
    /// out), and the nested message types it names.
    fn hashable_description(&self, kind: &str) -> (String, Vec<String>) {
        let mut nested = Vec::new();
        let mut fields = Vec::new();
        let empty = [Field {
            name: "structure_needs_at_least_one_member".into(),
            ty: FieldType {
                base: BaseType::Primitive(Primitive::Uint8),
                array: ArrayKind::Single,
            },
            default: None,
        }];
        let all: &[Field] = if self.fields.is_empty() { &empty } else { &self.fields };
        for field in all {
            let (base_id, string_capacity, nested_name) = match &field.ty.base {
                BaseType::Primitive(p) => (p.type_id(), 0, String::new()),
                BaseType::String { bound: None } => (type_id::STRING, 0, String::new()),
                BaseType::String { bound: Some(n) } => (type_id::BOUNDED_STRING, *n, String::new()),
                BaseType::Message { package, name } => {
                    let full = format!("{package}/msg/{name}");
                    nested.push(full.clone());
                    (type_id::NESTED_TYPE, 0, full)
                }
            };
            let (id, capacity) = match field.ty.array {
                ArrayKind::Single => (base_id, 0),
                ArrayKind::Fixed(n) => (base_id + type_id::ARRAY_OFFSET, n),
                ArrayKind::Bounded(n) => (base_id + type_id::BOUNDED_SEQUENCE_OFFSET, n),
                ArrayKind::Unbounded => (base_id + type_id::UNBOUNDED_SEQUENCE_OFFSET, 0),
            };
            fields.push(DescribedField {
                name: field.name.clone(),
                type_id: id,
                capacity,
                string_capacity,
                nested: nested_name,
            });
        }
        (describe(&self.type_name(kind), &fields), nested)
    }
}

/// One field of an individual type description (`type_description_interfaces/msg/Field`
/// without its default value).
struct DescribedField {
    name: String,
    type_id: u8,
    capacity: usize,
    string_capacity: usize,
    nested: String,
}

impl DescribedField {
    /// A field of the nested type `type_name` (`pkg/kind/Name`).
    fn nested(name: &str, type_name: &str) -> Self {
        Self::nested_array(name, type_id::NESTED_TYPE, 0, type_name)
    }

    fn nested_array(name: &str, type_id: u8, capacity: usize, type_name: &str) -> Self {
        Self {
            name: name.to_owned(),
            type_id,
            capacity,
            string_capacity: 0,
            nested: type_name.to_owned(),
        }
    }

    fn primitive(name: &str, p: Primitive) -> Self {
        Self {
            name: name.to_owned(),
            type_id: p.type_id(),
            capacity: 0,
            string_capacity: 0,
            nested: String::new(),
        }
    }
}

/// The hashable JSON of one individual type description.
fn describe(type_name: &str, fields: &[DescribedField]) -> String {
    let fields: Vec<String> = fields
        .iter()
        .map(|f| {
            format!(
                "{{\"name\": {}, \"type\": {{\"type_id\": {}, \"capacity\": {}, \"string_capacity\": {}, \"nested_type_name\": {}}}}}",
                json_string(&f.name),
                f.type_id,
                f.capacity,
                f.string_capacity,
                json_string(&f.nested)
            )
        })
        .collect();
    format!(
        "{{\"type_name\": {}, \"fields\": [{}]}}",
        json_string(type_name),
        fields.join(", ")
    )
}

/// A type description that no definition file spells out, and the types it nests.
fn synthetic(type_name: &str, fields: Vec<DescribedField>) -> (String, (String, Vec<String>)) {
    let nested = fields
        .iter()
        .filter(|f| !f.nested.is_empty())
        .map(|f| f.nested.clone())
        .collect();
    (type_name.to_owned(), (describe(type_name, &fields), nested))
}

const SERVICE_EVENT_INFO: &str = "service_msgs/msg/ServiceEventInfo";
const UUID: &str = "unique_identifier_msgs/msg/UUID";
const TIME: &str = "builtin_interfaces/msg/Time";

/// The types rosidl derives from a service `base` (`pkg/srv/Name`, or an action's
/// `pkg/action/Name_SendGoal`) whose request and response are `base_Request`, `base_Response`:
/// the event message `base_Event` (what service introspection publishes) and the service type
/// itself, whose three fields are the request, the response and the event.
fn service_types(base: &str) -> [(String, (String, Vec<String>)); 2] {
    let (request, response, event) = (
        format!("{base}_Request"),
        format!("{base}_Response"),
        format!("{base}_Event"),
    );
    // `Name_Request[<=1] request`, `Name_Response[<=1] response`: bounded sequences of one.
    let one = type_id::NESTED_TYPE + type_id::BOUNDED_SEQUENCE_OFFSET;
    [
        synthetic(
            &event,
            vec![
                DescribedField::nested("info", SERVICE_EVENT_INFO),
                DescribedField::nested_array("request", one, 1, &request),
                DescribedField::nested_array("response", one, 1, &response),
            ],
        ),
        synthetic(
            base,
            vec![
                DescribedField::nested("request_message", &request),
                DescribedField::nested("response_message", &response),
                DescribedField::nested("event_message", &event),
            ],
        ),
    ]
}

/// The types rosidl derives from an action `pkg/action/Name` with parts `Name_Goal`,
/// `Name_Result`, `Name_Feedback`: the goal and result services' requests and responses, the
/// two services, the feedback message of the feedback topic, and the action type itself.
fn action_types(base: &str) -> Vec<(String, (String, Vec<String>))> {
    let part = |suffix: &str| format!("{base}_{suffix}");
    let mut out = vec![
        synthetic(
            &part("SendGoal_Request"),
            vec![
                DescribedField::nested("goal_id", UUID),
                DescribedField::nested("goal", &part("Goal")),
            ],
        ),
        synthetic(
            &part("SendGoal_Response"),
            vec![
                DescribedField::primitive("accepted", Primitive::Bool),
                DescribedField::nested("stamp", TIME),
            ],
        ),
        synthetic(
            &part("GetResult_Request"),
            vec![DescribedField::nested("goal_id", UUID)],
        ),
        synthetic(
            &part("GetResult_Response"),
            vec![
                DescribedField::primitive("status", Primitive::Int8),
                DescribedField::nested("result", &part("Result")),
            ],
        ),
        synthetic(
            &part("FeedbackMessage"),
            vec![
                DescribedField::nested("goal_id", UUID),
                DescribedField::nested("feedback", &part("Feedback")),
            ],
        ),
        synthetic(
            base,
            vec![
                DescribedField::nested("goal", &part("Goal")),
                DescribedField::nested("result", &part("Result")),
                DescribedField::nested("feedback", &part("Feedback")),
                DescribedField::nested("send_goal_service", &part("SendGoal")),
                DescribedField::nested("get_result_service", &part("GetResult")),
                DescribedField::nested("feedback_message", &part("FeedbackMessage")),
            ],
        ),
    ];
    out.extend(service_types(&part("SendGoal")));
    out.extend(service_types(&part("GetResult")));
    out
}

impl Packages {
    /// Adds a message definition.
    pub fn add_message(&mut self, package: &str, name: &str, text: &str) -> Result<(), IdlError> {
        let spec = parse_msg(package, name, text)?;
        self.packages.entry(package.to_owned()).or_default().msgs.push(spec);
        Ok(())
    }

    /// Adds a service definition (`Name.srv` → `NameRequest`, `NameResponse`).
    pub fn add_service(&mut self, package: &str, name: &str, text: &str) -> Result<(), IdlError> {
        let (req, resp) = split_srv(text)?;
        let request = parse_msg(package, &format!("{name}_Request"), req)?;
        let response = parse_msg(package, &format!("{name}_Response"), resp)?;
        self.packages
            .entry(package.to_owned())
            .or_default()
            .srvs
            .push((name.to_owned(), request, response));
        Ok(())
    }

    /// Adds an action definition (`Name.action` → `NameGoal`, `NameResult`, `NameFeedback`, and
    /// the marker type `Name`).
    pub fn add_action(&mut self, package: &str, name: &str, text: &str) -> Result<(), IdlError> {
        let (goal, result, feedback) = split_action(text)?;
        let goal = parse_msg(package, &format!("{name}_Goal"), goal)?;
        let result = parse_msg(package, &format!("{name}_Result"), result)?;
        let feedback = parse_msg(package, &format!("{name}_Feedback"), feedback)?;
        self.packages
            .entry(package.to_owned())
            .or_default()
            .actions
            .push((name.to_owned(), goal, result, feedback));
        Ok(())
    }

    fn message_exists(&self, package: &str, name: &str) -> bool {
        self.packages
            .get(package)
            .is_some_and(|p| p.msgs.iter().any(|m| m.name == name))
    }

    fn rust_type(&self, ty: &FieldType, context: &str) -> Result<String, IdlError> {
        let element = match &ty.base {
            BaseType::Primitive(p) => p.rust().to_owned(),
            BaseType::String { .. } => "::std::string::String".to_owned(),
            BaseType::Message { package, name } => {
                if !self.message_exists(package, name) {
                    return Err(err(0, format!("{context}: unknown message type {package}/{name}")));
                }
                format!("crate::{package}::msg::{name}")
            }
        };
        Ok(match ty.array {
            ArrayKind::Single => element,
            ArrayKind::Fixed(n) => format!("[{element}; {n}]"),
            ArrayKind::Bounded(_) | ArrayKind::Unbounded => format!("::std::vec::Vec<{element}>"),
        })
    }

    fn default_expr(&self, field: &Field, context: &str) -> Result<String, IdlError> {
        let ctx = |m: String| err(0, format!("{context}.{}: {m}", field.name));
        let Some(value) = &field.default else {
            return Ok(match field.ty.array {
                ArrayKind::Fixed(_) => "::std::array::from_fn(|_| ::std::default::Default::default())".to_owned(),
                _ => "::std::default::Default::default()".to_owned(),
            });
        };
        let scalar = |v: &str| -> Result<String, IdlError> {
            match &field.ty.base {
                BaseType::Primitive(p) => p.literal(v).map_err(ctx),
                BaseType::String { .. } => Ok(format!("{:?}.to_owned()", unquote(v.trim()))),
                BaseType::Message { .. } => Err(ctx("messages cannot have default values".into())),
            }
        };
        match field.ty.array {
            ArrayKind::Single => scalar(value),
            array => {
                let inner = value
                    .trim()
                    .strip_prefix('[')
                    .and_then(|v| v.strip_suffix(']'))
                    .ok_or_else(|| ctx(format!("array default `{value}` must be written [a, b, …]")))?;
                let items: Vec<String> = inner
                    .split(',')
                    .map(str::trim)
                    .filter(|s| !s.is_empty())
                    .map(scalar)
                    .collect::<Result<_, _>>()?;
                match array {
                    ArrayKind::Fixed(n) if items.len() != n => {
                        Err(ctx(format!("default has {} values, the array {n}", items.len())))
                    }
                    ArrayKind::Fixed(_) => Ok(format!("[{}]", items.join(", "))),
                    ArrayKind::Bounded(n) if items.len() > n => {
                        Err(ctx(format!("default has {} values, the bound is {n}", items.len())))
                    }
                    _ => Ok(format!("vec![{}]", items.join(", "))),
                }
            }
        }
    }

    fn generate_struct(&self, out: &mut String, spec: &MsgSpec, module: &str) -> Result<(), IdlError> {
        let context = format!("{}/{}", spec.package, spec.name);
        let rust_name = spec.name.replace('_', "");
        let _ = writeln!(
            out,
            "    /// `{}/{module}/{}`, generated from its definition.",
            spec.package, spec.name
        );
        let _ = writeln!(
            out,
            "    #[derive(Debug, Clone, PartialEq, ::serde::Serialize, ::serde::Deserialize)]"
        );
        let _ = writeln!(out, "    pub struct {rust_name} {{");
        let mut defaults = Vec::new();
        if spec.fields.is_empty() {
            // The IDL mapping gives an empty structure one octet so it can be encoded.
            let _ = writeln!(out, "        pub structure_needs_at_least_one_member: u8,");
            defaults.push(("structure_needs_at_least_one_member".to_owned(), "0".to_owned()));
        }
        for field in &spec.fields {
            let ty = self.rust_type(&field.ty, &context)?;
            if matches!(field.ty.array, ArrayKind::Fixed(n) if n > 32) {
                let _ = writeln!(out, "        #[serde(with = \"::serde_big_array::BigArray\")]");
            }
            let name = rust_field_name(&field.name);
            let _ = writeln!(out, "        pub {name}: {ty},");
            defaults.push((name, self.default_expr(field, &context)?));
        }
        let _ = writeln!(out, "    }}\n");
        let _ = writeln!(out, "    impl ::std::default::Default for {rust_name} {{");
        let _ = writeln!(out, "        fn default() -> Self {{");
        let _ = writeln!(out, "            Self {{");
        for (name, expr) in defaults {
            let _ = writeln!(out, "                {name}: {expr},");
        }
        let _ = writeln!(out, "            }}\n        }}\n    }}\n");
        if !spec.constants.is_empty() {
            let _ = writeln!(out, "    impl {rust_name} {{");
            for c in &spec.constants {
                let (ty, value) = match &c.ty {
                    BaseType::Primitive(p) => (
                        p.rust().to_owned(),
                        p.literal(&c.value)
                            .map_err(|m| err(0, format!("{context}.{}: {m}", c.name)))?,
                    ),
                    BaseType::String { .. } => ("&'static str".to_owned(), format!("{:?}", c.value)),
                    BaseType::Message { .. } => {
                        return Err(err(0, format!("{context}.{}: constants must be primitive", c.name)))
                    }
                };
                let _ = writeln!(out, "        pub const {}: {ty} = {value};", c.name);
            }
            let _ = writeln!(out, "    }}\n");
        }
        let _ = writeln!(out, "    impl ::ros2_client::Message for {rust_name} {{}}\n");
        let _ = writeln!(out, "    impl crate::RosMessage for {rust_name} {{");
        let _ = writeln!(out, "        const PACKAGE: &'static str = {:?};", spec.package);
        let _ = writeln!(out, "        const NAME: &'static str = {:?};", spec.name);
        let _ = writeln!(out, "    }}\n");
        Ok(())
    }

    /// Generates the Rust source for every package.
    pub fn generate(&self) -> Result<String, IdlError> {
        let mut out = String::from("// Generated by msgs/rust/build.rs from .msg/.srv files. Do not edit.\n\n");
        for (package, contents) in &self.packages {
            let _ = writeln!(out, "/// Types of the ROS 2 package `{package}`.");
            let _ = writeln!(out, "pub mod {package} {{");
            if !contents.msgs.is_empty() {
                let _ = writeln!(out, "/// Messages of `{package}`.");
                let _ = writeln!(out, "pub mod msg {{");
                let mut msgs: Vec<&MsgSpec> = contents.msgs.iter().collect();
                msgs.sort_by(|a, b| a.name.cmp(&b.name));
                for spec in msgs {
                    self.generate_struct(&mut out, spec, "msg")?;
                }
                let _ = writeln!(out, "}}");
            }
            if !contents.srvs.is_empty() {
                let _ = writeln!(out, "/// Services of `{package}`.");
                let _ = writeln!(out, "pub mod srv {{");
                for (name, request, response) in &contents.srvs {
                    self.generate_struct(&mut out, request, "srv")?;
                    self.generate_struct(&mut out, response, "srv")?;
                    let _ = writeln!(out, "    /// The `{package}/srv/{name}` service.");
                    let _ = writeln!(out, "    #[derive(Debug, Clone, Copy, Default)]");
                    let _ = writeln!(out, "    pub struct {name};\n");
                    let _ = writeln!(out, "    impl crate::RosService for {name} {{");
                    let _ = writeln!(out, "        type Request = {name}Request;");
                    let _ = writeln!(out, "        type Response = {name}Response;");
                    let _ = writeln!(out, "        const PACKAGE: &'static str = {package:?};");
                    let _ = writeln!(out, "        const NAME: &'static str = {name:?};");
                    let _ = writeln!(out, "    }}\n");
                }
                let _ = writeln!(out, "}}");
            }
            if !contents.actions.is_empty() {
                let _ = writeln!(out, "/// Actions of `{package}`.");
                let _ = writeln!(out, "pub mod action {{");
                for (name, goal, result, feedback) in &contents.actions {
                    self.generate_struct(&mut out, goal, "action")?;
                    self.generate_struct(&mut out, result, "action")?;
                    self.generate_struct(&mut out, feedback, "action")?;
                    let _ = writeln!(out, "    /// The `{package}/action/{name}` action.");
                    let _ = writeln!(out, "    #[derive(Debug, Clone, Copy, Default)]");
                    let _ = writeln!(out, "    pub struct {name};\n");
                    let _ = writeln!(out, "    impl crate::RosAction for {name} {{");
                    let _ = writeln!(out, "        type Goal = {name}Goal;");
                    let _ = writeln!(out, "        type Result = {name}Result;");
                    let _ = writeln!(out, "        type Feedback = {name}Feedback;");
                    let _ = writeln!(out, "        const PACKAGE: &'static str = {package:?};");
                    let _ = writeln!(out, "        const NAME: &'static str = {name:?};");
                    let _ = writeln!(out, "    }}\n");
                }
                let _ = writeln!(out, "}}");
            }
            let _ = writeln!(out, "}}\n");
        }
        Ok(out)
    }
}

impl Packages {
    /// Every message type with its REP-2011 hashable type description: the type, then its
    /// nested message types' descriptions sorted by name, as
    /// `rosidl_generator_type_description` writes it (`json.dumps(…, separators=(', ', ': '))`,
    /// defaults left out). Service and action parts are described under `srv` / `action`, with
    /// the types rosidl derives from them: each service `pkg/srv/Name` and its `Name_Event`
    /// (which need `service_msgs/msg/ServiceEventInfo` to be built), each action `pkg/action/Name`
    /// with its `Name_SendGoal`, `Name_GetResult` services and `Name_FeedbackMessage` (which
    /// need `unique_identifier_msgs/msg/UUID`).
    pub fn hashable_descriptions(&self) -> Result<BTreeMap<String, String>, IdlError> {
        let mut by_name: BTreeMap<String, (String, Vec<String>)> = BTreeMap::new();
        let mut tops = Vec::new();
        for contents in self.packages.values() {
            for spec in &contents.msgs {
                by_name.insert(spec.type_name("msg"), spec.hashable_description("msg"));
                tops.push(spec.type_name("msg"));
            }
            for (name, request, response) in &contents.srvs {
                for spec in [request, response] {
                    by_name.insert(spec.type_name("srv"), spec.hashable_description("srv"));
                    tops.push(spec.type_name("srv"));
                }
                for (type_name, description) in service_types(&format!("{}/srv/{name}", request.package)) {
                    tops.push(type_name.clone());
                    by_name.insert(type_name, description);
                }
            }
            for (name, goal, result, feedback) in &contents.actions {
                for spec in [goal, result, feedback] {
                    by_name.insert(spec.type_name("action"), spec.hashable_description("action"));
                    tops.push(spec.type_name("action"));
                }
                for (type_name, description) in action_types(&format!("{}/action/{name}", goal.package)) {
                    tops.push(type_name.clone());
                    by_name.insert(type_name, description);
                }
            }
        }
        let mut out = BTreeMap::new();
        for top in tops {
            let mut seen = std::collections::BTreeSet::new();
            let mut stack = by_name[&top].1.clone();
            while let Some(name) = stack.pop() {
                if seen.insert(name.clone()) {
                    let (_, nested) = by_name.get(&name).ok_or_else(|| IdlError {
                        line: 0,
                        message: format!("{top} refers to {name}, which is not defined"),
                    })?;
                    stack.extend(nested.iter().cloned());
                }
            }
            let referenced: Vec<&str> = seen.iter().map(|n| by_name[n].0.as_str()).collect();
            out.insert(
                top.clone(),
                format!(
                    "{{\"type_description\": {}, \"referenced_type_descriptions\": [{}]}}",
                    by_name[&top].0,
                    referenced.join(", ")
                ),
            );
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_fields_arrays_constants_and_defaults() {
        let text = "\
# a comment
uint8 FLAT=0   # trailing comment
string GREETING=hello # not a comment in a string constant
std_msgs/Header header
float64[36] covariance
int32[] counts
uint8[<=4] small
string<=8 name \"x#y\"
float64 w 1
bool[2] flags [true, false]
Point[] points
";
        let m = parse_msg("pkg", "Demo", text).unwrap();
        assert_eq!(m.constants.len(), 2);
        assert_eq!(m.constants[0].value, "0");
        assert_eq!(m.constants[1].value, "hello # not a comment in a string constant");
        let ty = |i: usize| &m.fields[i].ty;
        assert_eq!(
            ty(0).base,
            BaseType::Message {
                package: "std_msgs".into(),
                name: "Header".into()
            }
        );
        assert_eq!(ty(1).array, ArrayKind::Fixed(36));
        assert_eq!(ty(2).array, ArrayKind::Unbounded);
        assert_eq!(ty(3).array, ArrayKind::Bounded(4));
        assert_eq!(ty(4).base, BaseType::String { bound: Some(8) });
        assert_eq!(m.fields[4].default.as_deref(), Some("\"x#y\""));
        assert_eq!(m.fields[5].default.as_deref(), Some("1"));
        assert_eq!(
            ty(7).base,
            BaseType::Message {
                package: "pkg".into(),
                name: "Point".into()
            }
        );
    }

    #[test]
    fn refuses_malformed_definitions() {
        assert!(parse_msg("p", "M", "float64").is_err());
        assert!(parse_msg("p", "M", "float64[x] a").is_err());
        assert!(parse_msg("p", "M", "float64[3 a").is_err());
        assert!(parse_msg("p", "M", "wstring a").is_err());
        assert!(parse_msg("p", "M", "int32 a\nint32 a").is_err());
        assert!(parse_msg("p", "M", "Point[] P=3").is_err());
        assert!(parse_msg("p", "M", "int32 9a").is_err());
        assert!(split_srv("int32 a\nint32 b").is_err());
        let e = parse_msg("p", "M", "int32 ok\nbad").unwrap_err();
        assert_eq!(e.line, 2);
    }

    #[test]
    fn literals_are_checked_against_their_type() {
        assert_eq!(Primitive::Uint8.literal("255").unwrap(), "255");
        assert!(Primitive::Uint8.literal("256").is_err());
        assert!(Primitive::Int8.literal("-129").is_err());
        assert_eq!(Primitive::Float64.literal("1").unwrap(), "1.0");
        assert!(Primitive::Float32.literal("nan").is_err());
        assert_eq!(Primitive::Bool.literal("True").unwrap(), "true");
    }

    #[test]
    fn generates_keyword_safe_fields_defaults_and_big_arrays() {
        let mut p = Packages::default();
        p.add_message("pkg", "Inner", "float64 w 1\n").unwrap();
        p.add_message("pkg", "Outer", "int32 type\nfloat64[40] big\nInner inner\nint32 K=-3\n")
            .unwrap();
        p.add_service("pkg", "Do", "Inner a\n---\nbool ok\n").unwrap();
        let code = p.generate().unwrap();
        assert!(code.contains("pub r#type: i32,"));
        assert!(code.contains("#[serde(with = \"::serde_big_array::BigArray\")]"));
        assert!(code.contains("w: 1.0,"));
        assert!(code.contains("pub const K: i32 = -3;"));
        assert!(code.contains("pub struct DoRequest") && code.contains("type Response = DoResponse;"));
        // An unknown nested type is an error, not code that fails to compile later.
        let mut bad = Packages::default();
        bad.add_message("pkg", "M", "Missing m\n").unwrap();
        assert!(bad
            .generate()
            .unwrap_err()
            .message
            .contains("unknown message type pkg/Missing"));
    }

    #[test]
    fn actions_split_into_goal_result_feedback() {
        let text = "float64 distance\nfloat64 speed 0.2\n---\nuint8 OK=0\nstring reason\n---\n";
        let (g, r, f) = split_action(text).unwrap();
        assert_eq!(
            (g, r, f),
            (
                "float64 distance\nfloat64 speed 0.2\n",
                "uint8 OK=0\nstring reason\n",
                ""
            )
        );
        assert!(split_action("int32 a\n---\nint32 b\n").is_err());
        assert!(split_action("a\n---\n---\n---\n").is_err());
        assert!(split_srv("int32 a\n---\nint32 b\n---\nint32 c\n").is_err());
        let mut p = Packages::default();
        p.add_message("pkg", "Inner", "float64 w\n").unwrap();
        p.add_action(
            "pkg",
            "Drive",
            text.replace("float64 speed", "Inner[] inner\nfloat64 speed").as_str(),
        )
        .unwrap();
        let code = p.generate().unwrap();
        assert!(code.contains("pub mod action {"));
        assert!(
            code.contains("pub struct DriveGoal {")
                && code.contains("pub inner: ::std::vec::Vec<crate::pkg::msg::Inner>,")
        );
        assert!(code.contains("speed: 0.2,"));
        assert!(code.contains("pub struct DriveResult {") && code.contains("pub const OK: u8 = 0;"));
        // The empty feedback gets the IDL's dummy octet.
        let feedback = &code[code.find("pub struct DriveFeedback {").unwrap()..];
        assert!(
            feedback.starts_with("pub struct DriveFeedback {\n        pub structure_needs_at_least_one_member: u8,")
        );
        assert!(code.contains("impl crate::RosAction for Drive {") && code.contains("type Feedback = DriveFeedback;"));
        assert!(code.contains("`pkg/action/Drive_Goal`"));
    }

    #[test]
    fn empty_messages_get_the_idl_dummy_member() {
        let mut p = Packages::default();
        p.add_message("pkg", "Empty", "# nothing\n").unwrap();
        assert!(p
            .generate()
            .unwrap()
            .contains("pub structure_needs_at_least_one_member: u8,"));
    }

    #[test]
    fn hashable_description_by_hand() {
        let mut p = Packages::default();
        p.add_message("pkg", "Inner", "uint8 A=1\nchar c\n").unwrap();
        p.add_message("pkg", "Outer", "string<=5 s\nint32[3] a\nInner[] inner\nbyte[<=2] b\n")
            .unwrap();
        p.add_message("pkg", "Empty", "").unwrap();
        let d = p.hashable_descriptions().unwrap();
        // REP-2011 field type ids: char is uint8 (3); string<=5 is BOUNDED_STRING (21) with
        // string_capacity 5; int32 (6) + ARRAY (48) = 54 with capacity 3; a nested type (1) +
        // UNBOUNDED_SEQUENCE (144) = 145; byte (16) + BOUNDED_SEQUENCE (96) = 112. Constants
        // are not fields.
        let inner = "{\"type_name\": \"pkg/msg/Inner\", \"fields\": [{\"name\": \"c\", \"type\": {\"type_id\": 3, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}]}";
        let outer = "{\"type_name\": \"pkg/msg/Outer\", \"fields\": [\
{\"name\": \"s\", \"type\": {\"type_id\": 21, \"capacity\": 0, \"string_capacity\": 5, \"nested_type_name\": \"\"}}, \
{\"name\": \"a\", \"type\": {\"type_id\": 54, \"capacity\": 3, \"string_capacity\": 0, \"nested_type_name\": \"\"}}, \
{\"name\": \"inner\", \"type\": {\"type_id\": 145, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"pkg/msg/Inner\"}}, \
{\"name\": \"b\", \"type\": {\"type_id\": 112, \"capacity\": 2, \"string_capacity\": 0, \"nested_type_name\": \"\"}}]}";
        assert_eq!(
            d["pkg/msg/Outer"],
            format!("{{\"type_description\": {outer}, \"referenced_type_descriptions\": [{inner}]}}")
        );
        // An empty message has the IDL mapping's one octet.
        assert!(d["pkg/msg/Empty"].contains("\"structure_needs_at_least_one_member\", \"type\": {\"type_id\": 3"));
    }

    #[test]
    fn service_and_action_types_rosidl_derives_by_hand() {
        let mut p = Packages::default();
        p.add_message("builtin_interfaces", "Time", "int32 sec\nuint32 nanosec\n")
            .unwrap();
        p.add_message(
            "service_msgs",
            "ServiceEventInfo",
            "uint8 event_type\nbuiltin_interfaces/Time stamp\nchar[16] client_gid\nint64 sequence_number\n",
        )
        .unwrap();
        p.add_message("unique_identifier_msgs", "UUID", "uint8[16] uuid\n")
            .unwrap();
        p.add_service("pkg", "Do", "bool a\n---\nbool b\n").unwrap();
        p.add_action("pkg", "Go", "bool g\n---\nbool r\n---\nbool f\n").unwrap();
        let d = p.hashable_descriptions().unwrap();
        let nested = |name: &str, ty: &str| {
            format!("{{\"name\": \"{name}\", \"type\": {{\"type_id\": 1, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"{ty}\"}}}}")
        };
        // `pkg/srv/Do`: request, response and event messages, each a nested type (1).
        let service = format!(
            "{{\"type_name\": \"pkg/srv/Do\", \"fields\": [{}, {}, {}]}}",
            nested("request_message", "pkg/srv/Do_Request"),
            nested("response_message", "pkg/srv/Do_Response"),
            nested("event_message", "pkg/srv/Do_Event")
        );
        assert!(d["pkg/srv/Do"].starts_with(&format!("{{\"type_description\": {service}, ")));
        // `Do_Event`: the event info, then request and response as sequences of at most one:
        // nested (1) + BOUNDED_SEQUENCE (96) = 97, capacity 1.
        let event = format!(
            "{{\"type_name\": \"pkg/srv/Do_Event\", \"fields\": [{}, \
{{\"name\": \"request\", \"type\": {{\"type_id\": 97, \"capacity\": 1, \"string_capacity\": 0, \"nested_type_name\": \"pkg/srv/Do_Request\"}}}}, \
{{\"name\": \"response\", \"type\": {{\"type_id\": 97, \"capacity\": 1, \"string_capacity\": 0, \"nested_type_name\": \"pkg/srv/Do_Response\"}}}}]}}",
            nested("info", "service_msgs/msg/ServiceEventInfo")
        );
        assert!(d["pkg/srv/Do_Event"].starts_with(&format!("{{\"type_description\": {event}, ")));
        // The service's references: the three messages, the event info and the Time it holds,
        // sorted by name.
        let refs = &d["pkg/srv/Do"][d["pkg/srv/Do"].find("referenced_type_descriptions").unwrap()..];
        let order: Vec<usize> = [
            "builtin_interfaces/msg/Time",
            "pkg/srv/Do_Event",
            "pkg/srv/Do_Request",
            "pkg/srv/Do_Response",
            "service_msgs/msg/ServiceEventInfo",
        ]
        .iter()
        .map(|n| {
            refs.find(&format!("{{\"type_name\": \"{n}\""))
                .unwrap_or_else(|| panic!("{n} not referenced"))
        })
        .collect();
        assert!(order.windows(2).all(|w| w[0] < w[1]), "{order:?}");
        // An action: `SendGoal_Response` is `bool accepted` (15) and the stamp; the feedback
        // message pairs the goal id with the feedback; the action type lists six parts.
        assert!(d["pkg/action/Go_SendGoal_Response"].starts_with(&format!(
            "{{\"type_description\": {{\"type_name\": \"pkg/action/Go_SendGoal_Response\", \"fields\": [\
{{\"name\": \"accepted\", \"type\": {{\"type_id\": 15, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}}}, {}]}}",
            nested("stamp", "builtin_interfaces/msg/Time")
        )));
        assert!(d["pkg/action/Go_FeedbackMessage"].starts_with(&format!(
            "{{\"type_description\": {{\"type_name\": \"pkg/action/Go_FeedbackMessage\", \"fields\": [{}, {}]}}",
            nested("goal_id", "unique_identifier_msgs/msg/UUID"),
            nested("feedback", "pkg/action/Go_Feedback")
        )));
        let action = &d["pkg/action/Go"];
        for (field, ty) in [
            ("goal", "Go_Goal"),
            ("result", "Go_Result"),
            ("feedback", "Go_Feedback"),
            ("send_goal_service", "Go_SendGoal"),
            ("get_result_service", "Go_GetResult"),
            ("feedback_message", "Go_FeedbackMessage"),
        ] {
            assert!(action.contains(&nested(field, &format!("pkg/action/{ty}"))), "{field}");
        }
        assert!(d.contains_key("pkg/action/Go_GetResult_Event"));
    }
}
