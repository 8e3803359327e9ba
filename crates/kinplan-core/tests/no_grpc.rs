//! House rule 1: the domain core never names tonic, prost or tokio. This test
//! reads the crate's own `Cargo.toml` and sources and fails naming the
//! dependency, or the file and line, that does.

use std::path::{Path, PathBuf};

/// The crates the core must not depend on or name (also as a prefix:
/// `tonic-build`, `prost_types`, `tokio_stream`, ...).
const FORBIDDEN: [&str; 3] = ["tonic", "prost", "tokio"];

/// True if `name` is a forbidden crate or one of its family.
fn forbidden(name: &str) -> Option<&'static str> {
    FORBIDDEN.into_iter().find(|f| {
        name == *f
            || name
                .strip_prefix(f)
                .is_some_and(|rest| rest.starts_with('-') || rest.starts_with('_'))
    })
}

/// The dependency names of every `[*dependencies*]` section of a manifest,
/// with their line numbers.
fn dependencies(manifest: &str) -> Vec<(usize, String)> {
    let mut in_dependencies = false;
    let mut names = Vec::new();
    for (i, line) in manifest.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if let Some(header) = line.strip_prefix('[') {
            let header = header.trim_end_matches(']');
            // `[dependencies]`, `[dev-dependencies]`, `[target.'cfg(..)'.dependencies]`,
            // or a table per dependency: `[dependencies.tokio]`.
            match header.rsplit_once("dependencies.") {
                Some((_, name)) => {
                    names.push((i + 1, name.trim_matches('"').to_string()));
                    in_dependencies = false;
                }
                None => in_dependencies = header.ends_with("dependencies"),
            }
        } else if in_dependencies && !line.is_empty() {
            let key = line.split(['=', '.']).next().unwrap_or("").trim();
            names.push((i + 1, key.trim_matches('"').to_string()));
        }
    }
    names
}

/// The identifiers of a line of Rust code outside `//` comments.
fn identifiers(line: &str) -> impl Iterator<Item = &str> {
    let code = match line.find("//") {
        Some(at) => &line[..at],
        None => line,
    };
    code.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .filter(|t| !t.is_empty())
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn the_manifest_has_no_grpc_dependency() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let named: Vec<String> = dependencies(&manifest)
        .into_iter()
        .filter(|(_, name)| forbidden(name).is_some())
        .map(|(line, name)| format!("Cargo.toml:{line}: depends on `{name}`"))
        .collect();
    assert!(
        named.is_empty(),
        "kinplan-core must not depend on tonic, prost or tokio:\n{}",
        named.join("\n")
    );
}

#[test]
fn no_source_file_names_tonic_prost_or_tokio() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    assert!(files.len() > 10, "found only {} source files", files.len());
    let mut named = Vec::new();
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        for (i, line) in text.lines().enumerate() {
            if let Some(name) = identifiers(line).find_map(forbidden) {
                let shown = file.strip_prefix(root).unwrap_or(&file).display();
                named.push(format!("{shown}:{}: names `{name}`: {}", i + 1, line.trim()));
            }
        }
    }
    assert!(
        named.is_empty(),
        "kinplan-core must not name tonic, prost or tokio:\n{}",
        named.join("\n")
    );
}

/// The checks themselves find what they look for.
#[test]
fn the_checks_catch_a_grpc_dependency_and_a_grpc_path() {
    let manifest = "[dependencies]\nnalgebra.workspace = true\ntokio = { version = \"1\" }\n\n\
                    [dev-dependencies]\nprost-types = \"0.14\"\n[dependencies.tonic]\nversion = \"0.14\"\n";
    let found: Vec<String> = dependencies(manifest)
        .into_iter()
        .filter(|(_, n)| forbidden(n).is_some())
        .map(|(_, n)| n)
        .collect();
    assert_eq!(found, ["tokio", "prost-types", "tonic"]);
    assert_eq!(
        identifiers("use tonic::Status; // prost").find_map(forbidden),
        Some("tonic")
    );
    assert_eq!(
        identifiers("let s = tokio_stream::empty();").find_map(forbidden),
        Some("tokio")
    );
    assert_eq!(
        identifiers("fn monotonically_rising() {} // tokio").find_map(forbidden),
        None
    );
}
