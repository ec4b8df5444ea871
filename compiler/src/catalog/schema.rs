//! The catalog format's vocabulary, written once: each element with its
//! attributes, the elements it may hold and where it belongs (for "not
//! allowed here"), and the value types. The reader ([`super::xml`]) checks
//! the element tree against it; `docs/catalog.md` is the format's reference
//! for users, and `compiler/tests/format_docs.rs` checks that it names every
//! element, attribute and type of these tables.

/// One element of the format.
pub struct ElementInfo {
    pub name: &'static str,
    pub attributes: &'static [&'static str],
    /// The elements allowed directly inside this one.
    pub children: &'static [&'static str],
    /// Where this element belongs, for "not allowed here" messages.
    pub belongs: &'static str,
}

const ROBOT_ATTRS: &[&str] = &["type", "aliases"];
const ROBOT_CHILDREN: &[&str] = &["Doc", "Platform", "Capability", "Value", "Service"];
const IN_ROBOT: &str = "inside `<Robot>`";

pub const ELEMENTS: &[ElementInfo] = &[
    ElementInfo {
        name: "Catalog",
        attributes: &[],
        children: &["Robot", "Operator"],
        belongs: "once, around the whole file",
    },
    ElementInfo {
        name: "Robot",
        attributes: ROBOT_ATTRS,
        children: ROBOT_CHILDREN,
        belongs: "directly inside `<Catalog>`",
    },
    ElementInfo {
        name: "Operator",
        attributes: ROBOT_ATTRS,
        children: ROBOT_CHILDREN,
        belongs: "directly inside `<Catalog>`",
    },
    ElementInfo {
        name: "Doc",
        attributes: &[],
        children: &[],
        belongs: "inside `<Robot>`, `<Value>` or `<Service>`",
    },
    ElementInfo {
        name: "Platform",
        attributes: &[
            "target", "os", "cpu", "cores", "clockMHz", "memoryKB", "note",
        ],
        children: &[],
        belongs: IN_ROBOT,
    },
    ElementInfo {
        name: "Capability",
        attributes: &["name"],
        children: &[],
        belongs: IN_ROBOT,
    },
    ElementInfo {
        name: "Value",
        attributes: &[
            "name", "type", "domain", "unit", "task", "graph", "doc", "aliases",
        ],
        children: &["Doc"],
        belongs: IN_ROBOT,
    },
    ElementInfo {
        name: "Service",
        attributes: &["name", "task", "graph", "doc", "aliases"],
        children: &["Doc", "Param", "Result", "Latency"],
        belongs: IN_ROBOT,
    },
    ElementInfo {
        name: "Latency",
        attributes: &["from", "to", "max"],
        children: &[],
        belongs: "inside a `<Service>` implemented by a task graph (`graph=`)",
    },
    ElementInfo {
        name: "Result",
        attributes: &["name", "type", "domain", "doc"],
        children: &[],
        belongs: "inside `<Service>`",
    },
    ElementInfo {
        name: "Param",
        attributes: &["name", "type", "optional", "domain"],
        children: &[],
        belongs: "inside `<Service>`",
    },
];

/// Each element with where it belongs: the shape [`crate::xmltree::Vocabulary`] reads.
pub(crate) const PLACES: [(&str, &str); ELEMENTS.len()] = places();

const fn places() -> [(&'static str, &'static str); ELEMENTS.len()] {
    let mut out = [("", ""); ELEMENTS.len()];
    let mut i = 0;
    while i < ELEMENTS.len() {
        out[i] = (ELEMENTS[i].name, ELEMENTS[i].belongs);
        i += 1;
    }
    out
}

pub(crate) fn element(name: &str) -> Option<&'static ElementInfo> {
    ELEMENTS.iter().find(|e| e.name == name)
}

/// The value types, for messages and did-you-mean.
pub const TYPE_NAMES: &[&str] = &[
    "int", "float", "bool", "string", "location", "image", "enum",
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_child_is_an_element_and_every_type_parses() {
        for e in ELEMENTS {
            for child in e.children {
                assert!(element(child).is_some(), "{}: {child}", e.name);
            }
        }
        for name in TYPE_NAMES.iter().filter(|t| **t != "enum") {
            assert!(
                super::super::ValueType::parse(name, None).is_some(),
                "{name}"
            );
        }
    }
}
