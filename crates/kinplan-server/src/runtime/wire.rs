//! The contract as data, for the checks that walk encoded messages against
//! it (request number ranges at admission, non-finite numbers in replies):
//! the descriptor set's messages by full name, and the protobuf varint.

use prost::Message;
use prost_types::{DescriptorProto, FileDescriptorSet};

use crate::pb;

/// The kinplan descriptor set, decoded.
pub fn descriptor_set() -> FileDescriptorSet {
    FileDescriptorSet::decode(pb::FILE_DESCRIPTOR_SET).expect("the built-in descriptor set decodes")
}

/// Calls `visit` with every message of `set` (nested ones included) and its
/// full name, e.g. `.kinplan.v1.Pose`.
pub fn each_message(set: &FileDescriptorSet, visit: &mut dyn FnMut(&str, &DescriptorProto)) {
    fn walk(prefix: &str, m: &DescriptorProto, visit: &mut dyn FnMut(&str, &DescriptorProto)) {
        let name = format!("{prefix}.{}", m.name());
        for nested in &m.nested_type {
            walk(&name, nested, visit);
        }
        visit(&name, m);
    }
    for file in &set.file {
        let package = format!(".{}", file.package());
        for m in &file.message_type {
            walk(&package, m, visit);
        }
    }
}

/// The base-128 varint at `*at`, advancing past it; `None` when the bytes end
/// first or it runs past 64 bits.
pub fn varint(bytes: &[u8], at: &mut usize) -> Option<u64> {
    let mut value = 0u64;
    for shift in (0..64).step_by(7) {
        let b = *bytes.get(*at)?;
        *at += 1;
        value |= u64::from(b & 0x7f) << shift;
        if b & 0x80 == 0 {
            return Some(value);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn varints_read_as_protobuf_writes_them() {
        for v in [0u64, 1, 127, 128, 300, u32::MAX as u64, u64::MAX] {
            let mut buf = Vec::new();
            prost::encoding::encode_varint(v, &mut buf);
            let mut at = 0;
            assert_eq!(varint(&buf, &mut at), Some(v));
            assert_eq!(at, buf.len());
        }
        assert_eq!(varint(&[0x80], &mut 0), None, "cut short");
    }

    #[test]
    fn nested_messages_get_their_full_names() {
        let mut names = Vec::new();
        each_message(&descriptor_set(), &mut |name, _| names.push(name.to_string()));
        assert!(names.iter().any(|n| n == ".kinplan.v1.Pose"));
        assert!(
            names
                .iter()
                .any(|n| n == ".kinplan.v1.PlanResponse.CriteriaEntry")
        );
    }
}
