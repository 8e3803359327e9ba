//! The MotionBenchMaker Panda problems for tests and the benchmark examples (Chamzas et al., RA-L
//! 2022; the archive `../shared/bench/mbm/panda_problems.tar.bz2` beside the
//! repository, which is read where it lies and never copied in).
//!
//! `.ci/test` extracts the archive into `target/mbm` and names the folder in
//! `KINPLAN_MBM_PROBLEMS`; elsewhere the tests look in `target/mbm/problems`
//! (extract it with `mkdir -p target/mbm && tar xjf
//! ../shared/bench/mbm/panda_problems.tar.bz2 -C target/mbm`) and are
//! skipped with a message when it is not there.

use std::path::PathBuf;

/// The folder of problem sets (`<set>_panda/sceneNNNN.yaml`,
/// `requestNNNN.yaml`), or `None` (with a message) when the problems are
/// not extracted. Panics when `KINPLAN_MBM_PROBLEMS` names a folder that is
/// not there: a run that was promised the data must not skip.
pub fn problems() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("KINPLAN_MBM_PROBLEMS") {
        let dir = PathBuf::from(dir);
        assert!(
            dir.join("box_panda").is_dir(),
            "KINPLAN_MBM_PROBLEMS={} holds no problem sets",
            dir.display()
        );
        return Some(dir);
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/mbm/problems");
    if dir.join("box_panda").is_dir() {
        return Some(dir);
    }
    eprintln!(
        "skipped: the MotionBenchMaker problems are not extracted in {} (see crates/kinplan-core/src/mbm_data.rs)",
        dir.display()
    );
    None
}

/// Problem `number`'s scene and request YAML of `set` (e.g. `"box"`).
pub fn problem(dir: &std::path::Path, set: &str, number: usize) -> (String, String) {
    let read = |kind: &str| {
        let path = dir.join(format!("{set}_panda/{kind}{number:04}.yaml"));
        std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    };
    (read("scene"), read("request"))
}

/// The seven problem sets.
pub const SETS: [&str; 7] = [
    "table_pick",
    "table_under_pick",
    "box",
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "cage",
];
