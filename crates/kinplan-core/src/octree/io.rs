//! OctoMap's `.bt` (binary, max-likelihood) and `.ot` (full, log-odds) formats and the
//! ROS `octomap_msgs/Octomap` node bytes, read iteratively with an explicit stack
//! bounded by the tree depth (docs/octree.md#file-and-message-formats).

use super::header::{BT_FIRST_LINE, Header, OT_FIRST_LINE, parse_header, write_header};
use super::key::TREE_DEPTH;
use super::tree::{Block, Loc, NONE, Node, ROOT};
use super::{Octree, OctreeError, OctreeLimits, SensorModel};

/// Two-bit child codes of the binary format: `(byte >> 2·(i mod 4)) & 3`.
const UNKNOWN: u8 = 0;
const FREE: u8 = 1;
const OCCUPIED: u8 = 2;
const INNER: u8 = 3;

impl Octree {
    /// Reads a `.bt` file (`# Octomap OcTree binary file`, id `OcTree` or
    /// `ColorOcTree`): free leaves get log-odds `clamp_min`, occupied ones `clamp_max`,
    /// inner nodes the maximum of their children (OctoMap's `readBinary`; a root without
    /// children reads as an occupied leaf, as in OctoMap). The header's `size` must equal
    /// the nodes read and stay within `limits.max_nodes`; nothing follows the last node.
    ///
    /// ```
    /// use kinplan_core::octree::{CellState, Octree, OctreeError, OctreeLimits};
    /// use nalgebra::Point3;
    /// let mut t = Octree::new(0.1).unwrap();
    /// let k = t.key_of(&Point3::new(0.25, 0.0, 1.0)).unwrap();
    /// assert_eq!(k, [32770, 32768, 32778]); // ⌊c/0.1⌋ + 32768
    /// t.update_key(&k, t.sensor_model().log_odds().hit);
    /// let bytes = t.write_bt();
    /// assert!(bytes.starts_with(b"# Octomap OcTree binary file\n"));
    /// let back = Octree::read_bt(&bytes, &OctreeLimits::default()).unwrap();
    /// assert_eq!(back.state_of_key(&k), CellState::Occupied);
    /// assert_eq!(back.num_nodes(), 17); // root + one node per level
    /// // a truncated stream is an error naming the offset, not a panic
    /// let cut = Octree::read_bt(&bytes[..bytes.len() - 1], &OctreeLimits::default());
    /// assert!(matches!(cut, Err(OctreeError::Truncated { .. })));
    /// ```
    pub fn read_bt(bytes: &[u8], limits: &OctreeLimits) -> Result<Octree, OctreeError> {
        let h = parse_header(bytes, BT_FIRST_LINE)?;
        if h.id != "OcTree" && h.id != "ColorOcTree" {
            return Err(OctreeError::UnsupportedTreeType {
                id: h.id,
                format: ".bt",
            });
        }
        read_body(bytes, &h, limits, true)
    }

    /// Reads a `.ot` file (`# Octomap OcTree file`, id `OcTree` or `ColorOcTree`):
    /// per node, depth first, an f32 log-odds (little-endian), for a `ColorOcTree`
    /// three colour bytes (r, g, b: read and dropped, as a colour has no say in
    /// occupancy), and a byte of child-exists bits.
    pub fn read_ot(bytes: &[u8], limits: &OctreeLimits) -> Result<Octree, OctreeError> {
        let h = parse_header(bytes, OT_FIRST_LINE)?;
        if h.id != "OcTree" && h.id != "ColorOcTree" {
            return Err(OctreeError::UnsupportedTreeType {
                id: h.id,
                format: ".ot",
            });
        }
        read_body(bytes, &h, limits, false)
    }

    /// Builds a tree from the fields of a ROS `octomap_msgs/Octomap` message: `binary`
    /// selects the `.bt` node bytes (else `.ot` node bytes), `id` the tree type,
    /// `resolution` (m) the cell size; `data` holds the node bytes only. An empty
    /// `data` is an empty tree.
    pub fn from_message_data(
        binary: bool,
        id: &str,
        resolution: f64,
        data: &[u8],
        limits: &OctreeLimits,
    ) -> Result<Octree, OctreeError> {
        let ok = id == "OcTree" || id == "ColorOcTree";
        if !ok {
            let format = if binary { "binary message" } else { "full message" };
            return Err(OctreeError::UnsupportedTreeType {
                id: id.into(),
                format,
            });
        }
        if !(resolution.is_finite() && resolution > 0.0) {
            return Err(OctreeError::BadResolution(resolution));
        }
        let mut t = Octree::with_sensor_model(resolution, SensorModel::default())?;
        limits.validate()?;
        if data.is_empty() {
            return Ok(t);
        }
        let end = if binary {
            read_binary_nodes(&mut t, data, 0, limits)?
        } else {
            read_full_nodes(&mut t, data, 0, limits, FullNode::of(id))?
        };
        if end != data.len() {
            return Err(OctreeError::TrailingBytes {
                offset: end,
                extra: data.len() - end,
            });
        }
        Ok(t)
    }

    /// The tree as a `.bt` file, as OctoMap's `writeBinary` writes it: converted to
    /// maximum likelihood and pruned first (on a copy; `self` is not changed).
    pub fn write_bt(&self) -> Vec<u8> {
        with_ml(self, |t| {
            let mut out = Vec::with_capacity(t.num_nodes / 4 + 256);
            write_header(&mut out, BT_FIRST_LINE, t.num_nodes, t.resolution);
            write_binary_nodes(t, &mut out);
            out
        })
    }

    /// The tree as a `.ot` file (full log-odds, every node, OctoMap's `write`).
    pub fn write_ot(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.num_nodes * 5 + 256);
        write_header(&mut out, OT_FIRST_LINE, self.num_nodes, self.resolution);
        write_full_nodes(self, &mut out);
        out
    }

    /// The `data` field of an `octomap_msgs/Octomap` message: binary (`.bt` node bytes
    /// of the max-likelihood pruned tree) or full (`.ot` node bytes); id is `OcTree`.
    pub fn to_message_data(&self, binary: bool) -> Vec<u8> {
        let mut out = Vec::new();
        if binary {
            with_ml(self, |t| write_binary_nodes(t, &mut out));
        } else {
            write_full_nodes(self, &mut out);
        }
        out
    }
}

fn with_ml<R>(t: &Octree, f: impl FnOnce(&Octree) -> R) -> R {
    if t.max_likelihood_pruned {
        f(t)
    } else {
        let mut c = t.clone();
        c.to_max_likelihood_pruned();
        f(&c)
    }
}

fn read_body(bytes: &[u8], h: &Header, limits: &OctreeLimits, binary: bool) -> Result<Octree, OctreeError> {
    limits.validate()?;
    if h.size > limits.max_nodes as u64 {
        return Err(OctreeError::TooManyNodes {
            limit: limits.max_nodes,
            offset: h.data_offset,
        });
    }
    let mut t = Octree::with_sensor_model(h.resolution, SensorModel::default())?;
    let end = if h.size == 0 {
        h.data_offset
    } else if binary {
        read_binary_nodes(&mut t, bytes, h.data_offset, limits)?
    } else {
        read_full_nodes(&mut t, bytes, h.data_offset, limits, FullNode::of(&h.id))?
    };
    if t.num_nodes as u64 != h.size {
        return Err(OctreeError::SizeMismatch {
            declared: h.size,
            actual: t.num_nodes as u64,
        });
    }
    if end != bytes.len() {
        return Err(OctreeError::TrailingBytes {
            offset: end,
            extra: bytes.len() - end,
        });
    }
    Ok(t)
}

#[inline]
fn take<const N: usize>(bytes: &[u8], pos: usize) -> Result<[u8; N], OctreeError> {
    match bytes.get(pos..pos + N) {
        Some(s) => Ok(s.try_into().expect("length N")),
        None => Err(OctreeError::Truncated {
            offset: bytes.len(),
            needed: pos + N - bytes.len(),
        }),
    }
}

fn check_count(t: &Octree, limits: &OctreeLimits, offset: usize) -> Result<(), OctreeError> {
    if t.num_nodes > limits.max_nodes {
        return Err(OctreeError::TooManyNodes {
            limit: limits.max_nodes,
            offset,
        });
    }
    Ok(())
}

/// Gives the node at `loc` the children coded by the two bytes `code`; returns the
/// mask of children that are inner nodes (their bytes follow).
fn make_binary_children(t: &mut Octree, loc: Loc, code: [u8; 2], offset: usize) -> Result<u8, OctreeError> {
    let word = code[0] as u16 | (code[1] as u16) << 8;
    let (lo, hi) = (t.model.clamp_min, t.model.clamp_max);
    let mut blk = Block {
        nodes: [Node::leaf(0.0); 8],
        mask: 0,
    };
    let mut inner = 0u8;
    for i in 0..8 {
        match ((word >> (2 * i)) & 3) as u8 {
            UNKNOWN => continue,
            FREE => blk.nodes[i] = Node::leaf(lo),
            OCCUPIED => blk.nodes[i] = Node::leaf(hi),
            _ => {
                blk.nodes[i] = Node::leaf(f32::NEG_INFINITY);
                inner |= 1 << i;
            }
        }
        blk.mask |= 1 << i;
    }
    if blk.mask == 0 {
        if loc == ROOT {
            t.node_mut(loc).value = hi;
            return Ok(0);
        }
        return Err(OctreeError::BadNodeData {
            offset,
            reason: "inner node without children",
        });
    }
    t.num_nodes += blk.mask.count_ones() as usize;
    let b = t.alloc_block(blk);
    t.node_mut(loc).block = b;
    Ok(inner)
}

/// Reads `.bt` node bytes from `pos`; returns the offset after the last node.
fn read_binary_nodes(
    t: &mut Octree,
    bytes: &[u8],
    mut pos: usize,
    limits: &OctreeLimits,
) -> Result<usize, OctreeError> {
    // every inner node costs 2 bytes, so the bytes present bound the blocks
    let avail = (bytes.len().saturating_sub(pos) / 2).min(limits.max_nodes / 8 + 1);
    t.blocks.reserve(avail);
    t.root = Some(Node::leaf(0.0));
    t.num_nodes = 1;
    let code = take::<2>(bytes, pos)?;
    let inner = make_binary_children(t, ROOT, code, pos)?;
    pos += 2;
    check_count(t, limits, pos)?;
    // frame: (location, inner-child mask, next child to look at, depth)
    let mut stack: Vec<(Loc, u8, u8, u8)> = Vec::with_capacity(TREE_DEPTH as usize + 1);
    stack.push((ROOT, inner, 0, 0));
    while let Some(top) = stack.last_mut() {
        let (loc, inner, next, depth) = *top;
        let rest = inner & !((1u16 << next) - 1) as u8;
        if rest == 0 {
            stack.pop();
            t.prune_value_only(loc);
            continue;
        }
        let i = rest.trailing_zeros() as u8;
        top.2 = i + 1;
        let child_depth = depth + 1;
        if child_depth >= TREE_DEPTH {
            return Err(OctreeError::TooDeep { offset: pos });
        }
        let child = t.node(loc).block * 8 + i as u32;
        let code = take::<2>(bytes, pos)?;
        let ci = make_binary_children(t, child, code, pos)?;
        pos += 2;
        check_count(t, limits, pos)?;
        stack.push((child, ci, 0, child_depth));
    }
    t.max_likelihood_pruned = true;
    Ok(pos)
}

/// The node record of a full (`.ot`) stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FullNode {
    /// `OcTree`: f32 log-odds, child bits.
    Plain,
    /// `ColorOcTree`: f32 log-odds, r, g, b, child bits.
    Color,
}

impl FullNode {
    fn of(id: &str) -> Self {
        if id == "ColorOcTree" {
            FullNode::Color
        } else {
            FullNode::Plain
        }
    }

    fn bytes(self) -> usize {
        match self {
            FullNode::Plain => 5,
            FullNode::Color => 8,
        }
    }
}

/// Reads `.ot` node bytes from `pos`; returns the offset after the last node.
fn read_full_nodes(
    t: &mut Octree,
    bytes: &[u8],
    mut pos: usize,
    limits: &OctreeLimits,
    node: FullNode,
) -> Result<usize, OctreeError> {
    let size = node.bytes();
    let avail = (bytes.len().saturating_sub(pos) / size).min(limits.max_nodes / 8 + 1);
    t.blocks.reserve(avail / 4);
    let read_node = |pos: usize| -> Result<(f32, u8), OctreeError> {
        let b = bytes.get(pos..pos + size).ok_or_else(|| OctreeError::Truncated {
            offset: bytes.len(),
            needed: pos + size - bytes.len(),
        })?;
        let v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        if !v.is_finite() {
            return Err(OctreeError::BadNodeData {
                offset: pos,
                reason: "log-odds value is not finite",
            });
        }
        Ok((v, b[size - 1]))
    };
    let (v, mask) = read_node(pos)?;
    pos += size;
    t.root = Some(Node::leaf(v));
    t.num_nodes = 1;
    let attach = |t: &mut Octree, loc: Loc, mask: u8| {
        if mask != 0 {
            let b = t.alloc_block(Block {
                nodes: [Node::leaf(0.0); 8],
                mask,
            });
            t.node_mut(loc).block = b;
        }
    };
    attach(t, ROOT, mask);
    let mut stack: Vec<(Loc, u8, u8, u8)> = Vec::with_capacity(TREE_DEPTH as usize + 1);
    stack.push((ROOT, mask, 0, 0));
    while let Some(top) = stack.last_mut() {
        let (loc, mask, next, depth) = *top;
        let rest = mask & !((1u16 << next) - 1) as u8;
        if rest == 0 {
            stack.pop();
            continue;
        }
        let i = rest.trailing_zeros() as u8;
        top.2 = i + 1;
        let child_depth = depth + 1;
        if child_depth > TREE_DEPTH {
            return Err(OctreeError::TooDeep { offset: pos });
        }
        let (v, cmask) = read_node(pos)?;
        if child_depth == TREE_DEPTH && cmask != 0 {
            return Err(OctreeError::TooDeep { offset: pos });
        }
        pos += size;
        t.num_nodes += 1;
        check_count(t, limits, pos)?;
        let child = t.node(loc).block * 8 + i as u32;
        *t.node_mut(child) = Node::leaf(v);
        attach(t, child, cmask);
        stack.push((child, cmask, 0, child_depth));
    }
    t.max_likelihood_pruned = false;
    Ok(pos)
}

impl Octree {
    /// Sets an inner node read from a file to the maximum of its children.
    fn prune_value_only(&mut self, loc: Loc) {
        let n = *self.node(loc);
        if n.block == NONE {
            return;
        }
        let b = &self.blocks[n.block as usize];
        let mut m = f32::NEG_INFINITY;
        for i in 0..8 {
            if b.mask & (1 << i) != 0 {
                m = m.max(b.nodes[i].value);
            }
        }
        self.node_mut(loc).value = m;
    }
}

fn code_of(t: &Octree, n: &Node) -> u8 {
    if n.has_children() {
        INNER
    } else if t.is_occupied_value(n.value) {
        OCCUPIED
    } else {
        FREE
    }
}

/// Writes `.bt` node bytes, depth first, parent before children.
fn write_binary_nodes(t: &Octree, out: &mut Vec<u8>) {
    let Some(root) = t.root else { return };
    let codes = |n: &Node| -> [u8; 2] {
        let mut w = 0u16;
        if n.has_children() {
            let b = &t.blocks[n.block as usize];
            for i in 0..8 {
                if b.mask & (1 << i) != 0 {
                    w |= (code_of(t, &b.nodes[i]) as u16) << (2 * i);
                }
            }
        }
        [w as u8, (w >> 8) as u8]
    };
    out.extend_from_slice(&codes(&root));
    let mut stack: Vec<(u32, u8)> = Vec::with_capacity(TREE_DEPTH as usize + 1);
    if root.has_children() {
        stack.push((root.block, 0));
    }
    while let Some(top) = stack.last_mut() {
        let (block, next) = *top;
        let b = &t.blocks[block as usize];
        let mut found = None;
        for i in next..8 {
            if b.mask & (1 << i) != 0 && b.nodes[i as usize].has_children() {
                found = Some(i);
                break;
            }
        }
        match found {
            None => {
                stack.pop();
            }
            Some(i) => {
                top.1 = i + 1;
                let c = b.nodes[i as usize];
                out.extend_from_slice(&codes(&c));
                stack.push((c.block, 0));
            }
        }
    }
}

/// Writes `.ot` node bytes: value then child-exists byte, depth first.
fn write_full_nodes(t: &Octree, out: &mut Vec<u8>) {
    let Some(root) = t.root else { return };
    let emit = |n: &Node, out: &mut Vec<u8>| {
        out.extend_from_slice(&n.value.to_le_bytes());
        out.push(if n.has_children() {
            t.blocks[n.block as usize].mask
        } else {
            0
        });
    };
    emit(&root, out);
    let mut stack: Vec<(u32, u8)> = Vec::with_capacity(TREE_DEPTH as usize + 1);
    if root.has_children() {
        stack.push((root.block, 0));
    }
    while let Some(top) = stack.last_mut() {
        let (block, next) = *top;
        let b = &t.blocks[block as usize];
        let rest = b.mask & !((1u16 << next) - 1) as u8;
        if rest == 0 {
            stack.pop();
            continue;
        }
        let i = rest.trailing_zeros() as u8;
        top.1 = i + 1;
        let c = b.nodes[i as usize];
        emit(&c, out);
        if c.has_children() {
            stack.push((c.block, 0));
        }
    }
}
