//! Generates the Rust message types from `.msg` / `.srv` / `.action` files at build time.
//!
//! Inputs: the suite's own interface package (`msgs/mobil_msgs`, package `mobil_msgs`), Nav2's Jazzy action types (`msgs/nav2_msgs`, package `nav2_msgs`), bond's
//! messages (`msgs/bond`, package `bond`) and the
//! standard ROS 2 Jazzy definitions the suite uses, vendored unchanged under `msgs/rust/ros`.
//! Output: `$OUT_DIR/generated.rs`, one module per package (`geometry_msgs::msg::Twist`, …),
//! with serde layouts that match the CDR encoding rmw implementations use (field order, fixed
//! arrays without a length prefix, sequences with one).
//!
//! The parser and code generator live in `src/idl.rs`, which is also compiled into the library
//! so that it is unit-tested like the rest of the code.

#[path = "src/idl.rs"]
mod idl;

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let msgs = manifest.join("..");
    let vendored = manifest.join("ros");

    let mut sources: Vec<(String, PathBuf)> = Vec::new();
    collect(&msgs.join("mobil_msgs"), "mobil_msgs", &mut sources);
    collect(&msgs.join("nav2_msgs"), "nav2_msgs", &mut sources);
    collect(&msgs.join("bond"), "bond", &mut sources);
    let mut std_packages: Vec<_> = std::fs::read_dir(&vendored)
        .expect("msgs/rust/ros exists")
        .filter_map(|e| e.ok())
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    std_packages.sort();
    for pkg in &std_packages {
        collect(&vendored.join(pkg), pkg, &mut sources);
    }

    let mut packages = idl::Packages::default();
    for (pkg, path) in &sources {
        println!("cargo:rerun-if-changed={}", path.display());
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .expect("utf-8 file name")
            .to_owned();
        let result = match path.extension().and_then(|e| e.to_str()) {
            Some("msg") => packages.add_message(pkg, &name, &text),
            Some("srv") => packages.add_service(pkg, &name, &text),
            Some("action") => packages.add_action(pkg, &name, &text),
            _ => continue,
        };
        if let Err(e) = result {
            panic!("{}: {e}", path.display());
        }
    }
    let mut code = packages
        .generate()
        .unwrap_or_else(|e| panic!("generating message types: {e}"));
    // REP-2011 type hashes: RIHS01_ and the SHA-256 of each hashable type description.
    let descriptions = packages
        .hashable_descriptions()
        .unwrap_or_else(|e| panic!("describing message types: {e}"));
    code.push_str(
        "/// REP-2011 type hashes (`RIHS01_` + SHA-256 of the hashable type description) of every\n\
         /// message, service part and action part, and of the service, event and action types\n\
         /// rosidl derives from them, sorted by type name (`pkg/msg/Name`).\n\
         pub static TYPE_HASHES: &[(&str, &str)] = &[\n",
    );
    for (name, json) in &descriptions {
        let digest = Sha256::digest(json.as_bytes());
        let hex: String = digest.iter().map(|b| format!("{b:02x}")).collect();
        code.push_str(&format!("    (\"{name}\", \"RIHS01_{hex}\"),\n"));
    }
    code.push_str("];\n");
    let out = PathBuf::from(std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR")).join("generated.rs");
    std::fs::write(&out, code).expect("writing generated.rs");
    println!("cargo:rerun-if-changed=src/idl.rs");
    println!("cargo:rerun-if-changed=ros");
    println!("cargo:rerun-if-changed=../mobil_msgs");
    println!("cargo:rerun-if-changed=../nav2_msgs");
    println!("cargo:rerun-if-changed=../bond");
}

fn collect(package_dir: &Path, pkg: &str, out: &mut Vec<(String, PathBuf)>) {
    for sub in ["msg", "srv", "action"] {
        let Ok(entries) = std::fs::read_dir(package_dir.join(sub)) else {
            continue;
        };
        let mut files: Vec<PathBuf> = entries.filter_map(|e| e.ok()).map(|e| e.path()).collect();
        files.sort();
        out.extend(files.into_iter().map(|p| (pkg.to_owned(), p)));
    }
}
