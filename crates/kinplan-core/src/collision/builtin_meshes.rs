//! Mesh files the library carries for its built-in robots, named in their
//! URDFs as `kinplan://builtin/<robot>/<link>.obj`: the grown convex hulls
//! of a real robot's collision meshes that `robot/builtin/fit_covers.py`
//! wrote. A model looks a mesh up here when the caller sent none under that
//! name, so a built-in robot needs no files and its URDF, sent back as text,
//! builds the same model.

use std::sync::OnceLock;

use super::mesh_file::{MeshFileLimits, read_mesh_file};
use super::model::InlineMesh;

/// The URI prefix of the embedded meshes.
pub const BUILTIN_MESH_SCHEME: &str = "kinplan://builtin/";

macro_rules! embedded {
    ($($path:literal),* $(,)?) => {
        const EMBEDDED: &[(&str, &[u8])] = &[
            $(($path, include_bytes!(concat!("../robot/builtin/meshes/", $path)))),*
        ];
    };
}

embedded!(
    "panda/base_link.obj",
    "panda/link_1.obj",
    "panda/link_2.obj",
    "panda/link_3.obj",
    "panda/link_4.obj",
    "panda/link_5.obj",
    "panda/link_6.obj",
    "panda/link_7.obj",
    "panda/panda_hand.obj",
);

/// The embedded mesh the URI `filename` names, if any.
pub fn builtin_mesh(filename: &str) -> Option<&'static InlineMesh> {
    static MESHES: OnceLock<Vec<InlineMesh>> = OnceLock::new();
    let path = filename.strip_prefix(BUILTIN_MESH_SCHEME)?;
    let meshes = MESHES.get_or_init(|| {
        EMBEDDED
            .iter()
            .map(|(path, bytes)| {
                read_mesh_file(
                    &format!("{BUILTIN_MESH_SCHEME}{path}"),
                    bytes,
                    &MeshFileLimits::default(),
                )
                .expect("the embedded meshes parse (checked by tests)")
            })
            .collect()
    });
    EMBEDDED.iter().position(|(p, _)| *p == path).map(|i| &meshes[i])
}
