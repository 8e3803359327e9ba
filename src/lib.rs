//! kinplan: kinematics, inverse kinematics, trajectory scoring and mobile-robot
//! control, as a plain library (the domain core) and a gRPC service on top.
//!
//! The domain rooms (`robot`, …) never name tonic or prost; `service` is the
//! only layer that does.

pub mod ik;
pub mod linalg;
pub mod mobile;
pub mod robot;
pub mod score;
pub mod service;

#[cfg(test)]
mod architecture {
    /// House rule 1: the domain rooms never name the transport crates.
    #[test]
    fn domain_rooms_do_not_name_tonic_or_prost() {
        let rooms = ["robot", "linalg", "ik", "plan", "nbv", "mobile", "score"];
        let banned = [
            concat!("ton", "ic::"),
            concat!("pro", "st::"),
            concat!("use ", "ton", "ic"),
        ];
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut stack: Vec<_> = rooms
            .iter()
            .map(|r| root.join(r))
            .filter(|p| p.exists())
            .collect();
        let mut checked = 0;
        while let Some(path) = stack.pop() {
            if path.is_dir() {
                stack.extend(std::fs::read_dir(&path).unwrap().map(|e| e.unwrap().path()));
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                for b in banned {
                    assert!(!text.contains(b), "{} names {b}", path.display());
                }
                checked += 1;
            }
        }
        assert!(checked > 5, "only {checked} files checked");
    }
}
