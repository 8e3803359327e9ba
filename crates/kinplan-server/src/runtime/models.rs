//! Resolves a `RobotRef` to a shared chain: built-in names, inline URDFs and
//! model ids. Parsed models sit in a bounded cache keyed by content hash; the
//! cache is only an optimisation, so any replica can answer any request that
//! carries its URDF.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use sha2::{Digest, Sha256};
use tonic::Status;

use super::{Budget, Compute};
use crate::pb::{self, robot_ref::Source};
use crate::status::{invalid, not_found, robot_error};
use kinplan_core::robot::{Chain, ChainSpec, Srdf, UrdfLimits, builtin_chain, parse_chain, parse_srdf};

/// A chain and the id a client can send instead of its URDF next time
/// (empty for built-in robots).
#[derive(Clone)]
pub struct Resolved {
    pub chain: Arc<Chain>,
    pub model_id: Vec<u8>,
    /// What the chain was parsed from: its other links (a gripper beyond the
    /// tip, a pedestal) and its mesh files belong to the collision model too.
    pub source: ModelSource,
    /// Values of joints off the chain, sorted by name (`RobotRef.held_joints`).
    pub held: HeldJoints,
}

/// Joint values held off the chain, sorted by name.
pub type HeldJoints = Arc<[(String, f64)]>;

/// The held joint values of a request, sorted by name (finite: the request
/// number check has seen them).
fn held_in(robot: &pb::RobotRef) -> HeldJoints {
    let mut held: Vec<(String, f64)> = robot.held_joints.iter().map(|(k, v)| (k.clone(), *v)).collect();
    held.sort_by(|a, b| a.0.cmp(&b.0));
    Arc::from(held)
}

/// A model as the client sent it: the URDF text and the mesh files it names,
/// as (URI, bytes) sorted by URI.
#[derive(Clone)]
pub struct ModelSource {
    pub urdf: Arc<str>,
    pub meshes: MeshFiles,
    /// MoveIt's SRDF for the URDF, when one was sent: read once, when the
    /// model arrives.
    pub srdf: Option<Arc<SrdfSource>>,
}

/// An SRDF as sent (its text is part of the model id) and as read.
pub struct SrdfSource {
    pub text: String,
    pub parsed: Srdf,
}

/// Mesh files as (URI, bytes), sorted by URI.
pub type MeshFiles = Arc<[(String, Vec<u8>)]>;

impl ModelSource {
    /// Bytes held (the cache's accounting).
    fn bytes(&self) -> usize {
        self.urdf.len()
            + self.srdf.as_ref().map_or(0, |s| s.text.len())
            + self.meshes.iter().map(|(u, d)| u.len() + d.len()).sum::<usize>()
    }

    /// The model id ([`model_id`]).
    async fn id(&self) -> ModelId {
        model_id(
            &self.urdf,
            self.srdf.as_ref().map(|s| s.text.as_str()),
            self.meshes
                .iter()
                .map(|(uri, data)| (uri.as_str(), data.as_slice())),
        )
        .await
    }
}

/// The model id: SHA-256 of the URDF text alone when there are no mesh files
/// and no SRDF (as before they could be sent), else of
/// `"kinplan-model-v1\0" · len·urdf · len·srdf · Σ_files(len·uri · len·data)`
/// with the files sorted by URI, every length a little-endian u64 and an
/// absent SRDF empty. Hashed [`HASH_SLICE`] bytes at a time, the runtime
/// given back between slices: a request of many megabytes of meshes does not
/// hold up the other calls its I/O thread serves.
async fn model_id<'a>(
    urdf: &str,
    srdf: Option<&str>,
    meshes: impl ExactSizeIterator<Item = (&'a str, &'a [u8])>,
) -> ModelId {
    let mut h = Sha256::new();
    if meshes.len() == 0 && srdf.is_none() {
        hash_yielding(&mut h, urdf.as_bytes()).await;
        return h.finalize().into();
    }
    h.update(b"kinplan-model-v1\0");
    let parts = [urdf.as_bytes(), srdf.unwrap_or("").as_bytes()]
        .into_iter()
        .chain(meshes.flat_map(|(uri, data)| [uri.as_bytes(), data]));
    for part in parts {
        h.update((part.len() as u64).to_le_bytes());
        hash_yielding(&mut h, part).await;
    }
    h.finalize().into()
}

/// Bytes hashed between two yields to the runtime.
const HASH_SLICE: usize = 128 << 10;

/// `h ← h · bytes`, yielding to the runtime after every [`HASH_SLICE`].
async fn hash_yielding(h: &mut Sha256, bytes: &[u8]) {
    for slice in bytes.chunks(HASH_SLICE) {
        h.update(slice);
        if slice.len() == HASH_SLICE {
            tokio::task::yield_now().await;
        }
    }
}

/// Most mesh files one model may carry.
pub const MAX_MESH_FILES: usize = 256;

/// The mesh files of a request, sorted by URI: at most [`MAX_MESH_FILES`],
/// each within the mesh reader's byte limit, no URI twice. Borrowed: a
/// model already held is found by its id without copying them.
fn meshes_in(files: &[pb::MeshFile]) -> Result<Vec<&pb::MeshFile>, Status> {
    if files.len() > MAX_MESH_FILES {
        return Err(invalid(
            "robot.meshes",
            format!("{} files exceed the limit of {MAX_MESH_FILES}", files.len()),
        ));
    }
    let max = kinplan_core::collision::MeshFileLimits::default().max_bytes;
    for (i, f) in files.iter().enumerate() {
        if f.uri.is_empty() {
            return Err(invalid(format!("robot.meshes[{i}].uri"), "is required"));
        }
        if f.data.len() > max {
            return Err(invalid(
                format!("robot.meshes[{}]", f.uri),
                format!("{} bytes exceed the limit of {max}", f.data.len()),
            ));
        }
    }
    let mut sorted: Vec<&pb::MeshFile> = files.iter().collect();
    sorted.sort_by(|a, b| a.uri.cmp(&b.uri));
    if let Some(w) = sorted.windows(2).find(|w| w[0].uri == w[1].uri) {
        return Err(invalid(format!("robot.meshes[{}]", w[0].uri), "is given twice"));
    }
    Ok(sorted)
}

/// An inline model as the request carries it (validated, files sorted by
/// URI), and its id.
struct Inline<'a> {
    urdf: &'a str,
    srdf: Option<&'a str>,
    meshes: Vec<&'a pb::MeshFile>,
}

impl Inline<'_> {
    async fn id(&self) -> ModelId {
        model_id(
            self.urdf,
            self.srdf,
            self.meshes.iter().map(|f| (f.uri.as_str(), f.data.as_slice())),
        )
        .await
    }

    /// The model's owned source, its SRDF read on the CPU pool (refused here
    /// when bad): built only when the model is not held already.
    async fn source(
        &self,
        limits: UrdfLimits,
        compute: &Compute,
        budget: &Budget,
    ) -> Result<ModelSource, Status> {
        let meshes: Vec<(String, Vec<u8>)> = self
            .meshes
            .iter()
            .map(|f| (f.uri.clone(), f.data.clone()))
            .collect();
        let srdf = match self.srdf {
            None => None,
            Some(text) => {
                let text = text.to_string();
                let read = compute
                    .run(budget, move |_| {
                        let parsed = parse_srdf(&text, &limits)?;
                        Ok(SrdfSource { text, parsed })
                    })
                    .await?
                    .map_err(|e| robot_error(e, ""))?;
                Some(Arc::new(read))
            }
        };
        Ok(ModelSource {
            urdf: Arc::from(self.urdf),
            meshes: Arc::from(meshes),
            srdf,
        })
    }
}

/// The chain of the SRDF group `group`: its (first) `<chain>`.
fn group_chain(source: &ModelSource, group: &str) -> Result<ChainSpec, Status> {
    let Some(srdf) = &source.srdf else {
        return Err(invalid(
            "robot.group",
            "names an SRDF group, and the model has no SRDF",
        ));
    };
    let found = srdf
        .parsed
        .group(group)
        .ok_or_else(|| invalid("robot.group", format!("the SRDF has no group `{group}`")))?;
    let (base, tip) = found
        .chains
        .first()
        .ok_or_else(|| invalid("robot.group", format!("group `{group}` has no <chain>")))?;
    Ok(ChainSpec {
        base_link: Some(base.clone()),
        tip_link: Some(tip.clone()),
    })
}

/// A parsed chain and what it came from.
type ParsedChain = (Arc<Chain>, ModelSource);

/// The source of a built-in robot: its URDF text and, when it has one, its
/// SRDF (designed contacts), read once and shared (not copied per request).
fn builtin_source(name: &str) -> Result<ModelSource, Status> {
    type Texts = HashMap<&'static str, (Arc<str>, Option<Arc<SrdfSource>>)>;
    static TEXTS: std::sync::OnceLock<Texts> = std::sync::OnceLock::new();
    let texts = TEXTS.get_or_init(|| {
        kinplan_core::robot::BUILTIN_NAMES
            .iter()
            .filter_map(|n| {
                let urdf = Arc::<str>::from(kinplan_core::robot::builtin_urdf(n).ok()?);
                let srdf =
                    kinplan_core::robot::builtin_srdf(n).zip(kinplan_core::robot::builtin_srdf_parsed(n));
                let srdf = srdf.map(|(text, parsed)| {
                    Arc::new(SrdfSource {
                        text: text.to_string(),
                        parsed: parsed.clone(),
                    })
                });
                Some((*n, (urdf, srdf)))
            })
            .collect()
    });
    kinplan_core::robot::builtin_urdf(name).map_err(|e| robot_error(e, ""))?;
    let (urdf, srdf) = texts
        .get(name)
        .cloned()
        .ok_or_else(|| invalid("robot.name", "a built-in robot without its URDF"))?;
    Ok(ModelSource {
        urdf,
        meshes: Arc::from(Vec::new()),
        srdf,
    })
}

/// A small least-recently-used map, bounded in entries and in bytes (each
/// value's size as given on insertion).
struct Lru<K, V> {
    entries: HashMap<K, (V, u64, usize)>,
    capacity: usize,
    max_bytes: usize,
    bytes: usize,
    tick: u64,
}

impl<K: std::hash::Hash + Eq + Clone, V: Clone> Lru<K, V> {
    fn new(capacity: usize, max_bytes: usize) -> Self {
        Self {
            entries: HashMap::new(),
            capacity: capacity.max(1),
            max_bytes,
            bytes: 0,
            tick: 0,
        }
    }

    fn evict_oldest(&mut self) {
        let oldest = self
            .entries
            .iter()
            .min_by_key(|(_, (_, used, _))| *used)
            .map(|(k, _)| k.clone());
        if let Some(k) = oldest
            && let Some((_, _, size)) = self.entries.remove(&k)
        {
            self.bytes -= size;
        }
    }

    fn get(&mut self, key: &K) -> Option<V> {
        self.tick += 1;
        let tick = self.tick;
        self.entries.get_mut(key).map(|(v, used, _)| {
            *used = tick;
            v.clone()
        })
    }

    /// Keeps `value` (of `size` bytes) unless it alone exceeds the byte bound;
    /// evicts the least recently used entries to make room.
    fn insert(&mut self, key: K, value: V, size: usize) {
        self.tick += 1;
        if let Some((_, _, old)) = self.entries.remove(&key) {
            self.bytes -= old;
        }
        if size > self.max_bytes {
            return;
        }
        while !self.entries.is_empty()
            && (self.entries.len() >= self.capacity || self.bytes + size > self.max_bytes)
        {
            self.evict_oldest();
        }
        self.bytes += size;
        self.entries.insert(key, (value, self.tick, size));
    }
}

/// Bytes a parsed chain holds, roughly: its frames, joints and shapes.
fn chain_bytes(chain: &Chain) -> usize {
    let shapes: usize = chain.collision().iter().map(|c| c.shapes.len()).sum();
    std::mem::size_of::<Chain>() + chain.links().len() * 256 + chain.joints().len() * 256 + shapes * 128
}

type ModelId = [u8; 32];

/// Parsed models and the URDF texts behind them, both bounded.
pub struct ModelStore {
    limits: UrdfLimits,
    /// Parsed chains with the text they came from (its other links collide too).
    chains: Mutex<Lru<(ModelId, ChainSpec), ParsedChain>>,
    texts: Mutex<Lru<ModelId, ModelSource>>,
}

impl ModelStore {
    /// At most `capacity` models, and at most `max_bytes` of URDF text plus
    /// parsed chains in all (half for each).
    pub fn new(limits: UrdfLimits, capacity: usize, max_bytes: usize) -> Self {
        Self {
            limits,
            chains: Mutex::new(Lru::new(capacity, max_bytes / 2)),
            texts: Mutex::new(Lru::new(capacity, max_bytes / 2)),
        }
    }

    /// Bytes held by the cache now (texts and chains).
    pub fn bytes(&self) -> usize {
        self.chains.lock().expect("cache lock").bytes + self.texts.lock().expect("cache lock").bytes
    }

    /// The chain a request names; parses (on the CPU pool) only on a miss.
    pub async fn resolve(
        &self,
        robot: Option<&pb::RobotRef>,
        compute: &Compute,
        budget: &Budget,
    ) -> Result<Resolved, Status> {
        let Some(robot) = robot else {
            return Err(invalid("robot", "is required"));
        };
        let mut spec = ChainSpec {
            base_link: Some(robot.base_link.clone()).filter(|s| !s.is_empty()),
            tip_link: Some(robot.tip_link.clone()).filter(|s| !s.is_empty()),
        };
        let inline = matches!(robot.source, Some(Source::Urdf(_)));
        if !robot.meshes.is_empty() && !inline {
            return Err(invalid(
                "robot.meshes",
                "mesh files come with an inline urdf (a model id already names them)",
            ));
        }
        if !robot.srdf.is_empty() && !inline {
            return Err(invalid(
                "robot.srdf",
                "an SRDF comes with an inline urdf (a model id already names it)",
            ));
        }
        if !robot.group.is_empty() && spec != ChainSpec::default() {
            return Err(invalid(
                "robot.group",
                "names the chain: leave base_link and tip_link empty",
            ));
        }
        let mut inline = None;
        let (id, text) = match &robot.source {
            None => return Err(invalid("robot", "one of name, urdf or model_id is required")),
            Some(Source::Name(name)) => {
                if spec == ChainSpec::default() && robot.group.is_empty() {
                    let chain = builtin_chain(name).map_err(|e| robot_error(e, ""))?;
                    return Ok(Resolved {
                        chain,
                        model_id: Vec::new(),
                        source: builtin_source(name)?,
                        held: held_in(robot),
                    });
                }
                // Another chain of a built-in: parsed once, then cached like any URDF.
                let source = builtin_source(name)?;
                (source.id().await, Some(source))
            }
            Some(Source::Urdf(text)) => {
                for (field, len) in [("robot.urdf", text.len()), ("robot.srdf", robot.srdf.len())] {
                    if len > self.limits.max_bytes {
                        return Err(invalid(
                            field,
                            format!("{len} bytes exceed the limit of {}", self.limits.max_bytes),
                        ));
                    }
                }
                let sent = Inline {
                    urdf: text,
                    srdf: Some(robot.srdf.as_str()).filter(|s| !s.is_empty()),
                    meshes: meshes_in(&robot.meshes)?,
                };
                let id = sent.id().await;
                inline = Some(sent);
                (id, None)
            }
            Some(Source::ModelId(bytes)) => {
                let id: ModelId = bytes.as_slice().try_into().map_err(|_| {
                    invalid("robot.model_id", format!("must be 32 bytes, got {}", bytes.len()))
                })?;
                (id, None)
            }
        };
        // Built-in robots are named, not identified by hash.
        let model_id = match &robot.source {
            Some(Source::Name(_)) => Vec::new(),
            _ => id.to_vec(),
        };
        // The source behind the id: held already, or read from the request
        // (its files copied, its SRDF parsed, so a bad one is refused on the
        // call that sends it); a model this replica holds is not read again.
        let held_or_sent = async || {
            let held = self.texts.lock().expect("cache lock").get(&id);
            match (held, &inline) {
                (Some(held), _) => Ok(held),
                (None, Some(sent)) => sent.source(self.limits, compute, budget).await,
                (None, None) => Err(not_found(
                    "robot.model_id",
                    "this server does not hold that model; send the URDF again",
                )),
            }
        };
        let text = match text {
            Some(t) => Some(t),
            None if !robot.group.is_empty() => Some(held_or_sent().await?),
            None => None,
        };
        if !robot.group.is_empty() {
            let source = text.as_ref().expect("fetched above");
            spec = group_chain(source, &robot.group)?;
        }
        let key = (id, spec.clone());
        if let Some((chain, source)) = self.chains.lock().expect("cache lock").get(&key) {
            return Ok(Resolved {
                chain,
                model_id,
                source,
                held: held_in(robot),
            });
        }
        let text = match text {
            Some(t) => t,
            None => held_or_sent().await?,
        };
        let chain = self.parse(text.urdf.clone(), spec, compute, budget).await?;
        let text_bytes = text.bytes();
        self.texts
            .lock()
            .expect("cache lock")
            .insert(id, text.clone(), text_bytes);
        // the source is counted again here: a chain entry keeps it alive
        let size = chain_bytes(&chain) + text_bytes;
        self.chains
            .lock()
            .expect("cache lock")
            .insert(key, (chain.clone(), text.clone()), size);
        Ok(Resolved {
            chain,
            model_id,
            source: text,
            held: held_in(robot),
        })
    }

    async fn parse(
        &self,
        text: Arc<str>,
        spec: ChainSpec,
        compute: &Compute,
        budget: &Budget,
    ) -> Result<Arc<Chain>, Status> {
        let limits = self.limits;
        compute
            .run(budget, move |_| parse_chain(&text, &spec, limits))
            .await?
            .map(Arc::new)
            .map_err(|e| robot_error(e, ""))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn named(name: &str, tip: &str) -> pb::RobotRef {
        pb::RobotRef {
            source: Some(Source::Name(name.into())),
            tip_link: tip.into(),
            ..Default::default()
        }
    }

    /// A built-in's other chain, or an inline URDF, is parsed once and then served
    /// from the cache (the same shared chain comes back).
    #[tokio::test]
    async fn models_are_parsed_once() {
        let store = ModelStore::new(UrdfLimits::default(), 8, 64 << 20);
        let compute = Compute::new(1, 4, None);
        let budget = Budget::new(None);
        let flange = named("kuka_kr210_r2700_extra", "flange");
        let a = store.resolve(Some(&flange), &compute, &budget).await.unwrap();
        let b = store.resolve(Some(&flange), &compute, &budget).await.unwrap();
        assert!(Arc::ptr_eq(&a.chain, &b.chain));
        assert_eq!(a.chain.tip_link(), "flange");
        assert!(a.model_id.is_empty());
        let default = store
            .resolve(Some(&named("kuka_kr210_r2700_extra", "")), &compute, &budget)
            .await
            .unwrap();
        assert_eq!(default.chain.tip_link(), "tool0");
        assert!(!Arc::ptr_eq(&a.chain, &default.chain));

        let inline = pb::RobotRef {
            source: Some(Source::Urdf(
                kinplan_core::robot::builtin_urdf("ur5").unwrap().into(),
            )),
            ..Default::default()
        };
        let c = store.resolve(Some(&inline), &compute, &budget).await.unwrap();
        let by_id = pb::RobotRef {
            source: Some(Source::ModelId(c.model_id.clone())),
            ..Default::default()
        };
        let d = store.resolve(Some(&by_id), &compute, &budget).await.unwrap();
        assert!(Arc::ptr_eq(&c.chain, &d.chain));
        assert_eq!(c.model_id.len(), 32);
    }

    /// Regression: the cache bounded entries, not bytes (300 URDFs of 1.9 MB
    /// kept 602 MB). Now its bytes stay under the configured bound.
    #[tokio::test]
    async fn the_cache_is_bounded_in_bytes() {
        let max = 1 << 20;
        let store = ModelStore::new(UrdfLimits::default(), 1000, max);
        let compute = Compute::new(1, 4, None);
        let budget = Budget::new(None);
        let padding = format!("<!-- {} -->", "x".repeat(100_000));
        for k in 0..40 {
            let urdf = format!(r#"<robot name="r{k}">{padding}<link name="a"/></robot>"#);
            let inline = pb::RobotRef {
                source: Some(Source::Urdf(urdf)),
                ..Default::default()
            };
            store.resolve(Some(&inline), &compute, &budget).await.unwrap();
            assert!(store.bytes() <= max, "{} bytes after {k} models", store.bytes());
        }
        assert!(store.bytes() > max / 4, "the cache still holds models");
    }

    /// An inline model with mesh files (one of several hashing slices) and an
    /// SRDF: its id is SHA-256 over the documented layout (written out here
    /// byte by byte), whatever order the files come in; sent again it is the
    /// model held (the same chain and source, not read again); the same URDF
    /// with a broken SRDF is another model, refused on the call that sends it.
    #[tokio::test]
    async fn an_inline_model_is_named_by_its_content_and_read_once() {
        let store = ModelStore::new(UrdfLimits::default(), 8, 64 << 20);
        let compute = Compute::new(1, 4, None);
        let budget = Budget::new(None);
        let urdf = kinplan_core::robot::builtin_urdf("ur5").unwrap();
        let srdf = r#"<robot name="ur5"><disable_collisions link1="base_link" link2="shoulder_link" reason="Adjacent"/></robot>"#;
        let file = |uri: &str, data: &[u8]| pb::MeshFile {
            uri: uri.into(),
            data: data.to_vec(),
        };
        let sent = |srdf: &str, files: Vec<pb::MeshFile>| pb::RobotRef {
            source: Some(Source::Urdf(urdf.into())),
            srdf: srdf.into(),
            meshes: files,
            ..Default::default()
        };
        // a file of several hashing slices, not a whole number of them
        let big: Vec<u8> = (0..2 * HASH_SLICE + 12_345)
            .map(|i| (i * 7 % 251) as u8)
            .collect();
        let (a, b) = (file("package://m/b.stl", &big), file("package://m/a.stl", b"ay"));
        let first = store
            .resolve(Some(&sent(srdf, vec![a.clone(), b.clone()])), &compute, &budget)
            .await
            .unwrap();

        let mut bytes = b"kinplan-model-v1\0".to_vec();
        for part in [
            urdf.as_bytes(),
            srdf.as_bytes(),
            b"package://m/a.stl",
            b"ay",
            b"package://m/b.stl",
            &big,
        ] {
            bytes.extend_from_slice(&(part.len() as u64).to_le_bytes());
            bytes.extend_from_slice(part);
        }
        assert_eq!(first.model_id, Sha256::digest(&bytes).to_vec());

        let again = store
            .resolve(Some(&sent(srdf, vec![b, a.clone()])), &compute, &budget)
            .await
            .unwrap();
        assert_eq!(again.model_id, first.model_id);
        assert!(Arc::ptr_eq(&again.chain, &first.chain));
        assert!(Arc::ptr_eq(&again.source.meshes, &first.source.meshes));

        let err = store
            .resolve(Some(&sent("<robot", vec![a])), &compute, &budget)
            .await
            .err()
            .expect("a broken SRDF is refused");
        assert_eq!(err.code(), tonic::Code::InvalidArgument);
        assert!(err.message().to_lowercase().contains("srdf"), "{}", err.message());
    }
}
