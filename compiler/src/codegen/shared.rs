//! The library task `lib_<name>.c`: the team's shared information, and for
//! its globally shared values the owner protocol of
//! `docs/shared-information.md` (refinement's `Ownership`): one robot of the
//! team owns them; a write elsewhere goes to the owner (`Team.__set.X`), the
//! owner tells the team every value it takes (`Team.__value.X`), and the
//! first live robot of the owner order takes over from a lost owner (no
//! heartbeat for `lost_after_ms`), telling the team the values it last saw.
//! The simulator does the same (`sim/engine/shared.rs`).

use super::c;
use super::peers::Peers;
use super::template::{Template, fill, template};
use super::values::Words;
use super::{Layer, Target};
use crate::refine::graph::{CONTROL_TASK, getter, setter};
use crate::refine::{AttributeId, OwnerRule, Ownership, RobotProgram, SharedLibrary, ValueKind};
use std::fmt::Write;

/// The C prefix of the library's functions.
pub(super) fn prefix(lib: &SharedLibrary) -> String {
    c::ident(&lib.name)
}

/// `program.h`: the library's functions.
pub fn declarations(program: &RobotProgram) -> String {
    let Some(lib) = &program.library else {
        return String::new();
    };
    let prefix = prefix(lib);
    let mut out = format!(
        "\n/* Library task {}: the team's shared information. */\n",
        c::comment(&lib.name)
    );
    for key in &lib.attributes {
        let _ = writeln!(
            out,
            "LIBFUNC(semo_value, {prefix}_{}, (void));\nLIBFUNC(void, {prefix}_{}, (const semo_value *value));",
            getter(key),
            setter(key)
        );
    }
    if lib.ownership.is_some() {
        out.push_str(&fill(&OWNER_DECLARATIONS, &[("prefix", &prefix)]));
    }
    out
}

/// `program.h`'s declarations of the owner protocol's functions.
const OWNER_DECLARATIONS: Template = template!("shared/owner_declarations.h.in", ["prefix"]);
/// `lib_<Team>Shared.c`'s values, and a value's getter and setter: of this
/// robot's alone, or globally shared (through the owner).
const LIBRARY_HEAD: Template = template!("shared/library_head.c.in", ["name", "declare", "count"]);
const LOCAL_VALUE: Template = template!(
    "shared/local_value.c.in",
    ["prefix", "getter", "setter", "i", "lock", "unlock"]
);
const GLOBAL_VALUE: Template = template!(
    "shared/global_value.c.in",
    [
        "prefix", "getter", "setter", "key", "i", "k", "lock", "unlock"
    ]
);
/// The owner protocol's tables of globally shared values.
const GLOBALS: Template = template!(
    "shared/globals.c.in",
    ["at", "names", "set_keys", "value_keys", "types"]
);
const OWNERS: Template = template!("shared/owners.c.in", ["owners", "first"]);
/// `tell`, `current_owner` and `<prefix>_owner_lost_at`.
const TELL: Template = template!(
    "shared/tell.c.in",
    ["name", "follow", "prefix", "lock", "unlock", "lost"]
);
/// `current_owner`'s choice of who follows a lost owner, per rule.
const FOLLOW_FIRST: Template = template!("shared/follow_first.c.in", ["lost"]);
const FOLLOW_BATTERY: Template = template!("shared/follow_battery.c.in", ["lost"]);
/// `<prefix>_heard`.
const HEARD: Template = template!("shared/heard.c.in", ["prefix", "lock", "unlock", "wake"]);

/// Every template of the library task's owner protocol.
#[cfg(test)]
pub(super) const TEMPLATES: &[Template] = &[
    OWNER_DECLARATIONS,
    LIBRARY_HEAD,
    LOCAL_VALUE,
    GLOBAL_VALUE,
    GLOBALS,
    OWNERS,
    TELL,
    FOLLOW_FIRST,
    FOLLOW_BATTERY,
    HEARD,
];

/// The line of `comm_task.c`'s receive body that hands the owner protocol's
/// messages to the library.
pub fn comm_dispatch(program: &RobotProgram) -> Option<String> {
    let lib = program.library.as_ref()?;
    lib.ownership.as_ref()?;
    Some(format!(
        "    if ({}_heard(&m))\n        return;\n",
        prefix(lib)
    ))
}

/// `lib_<name>.c`.
pub fn library_c(
    program: &RobotProgram,
    peers: &Peers,
    target: Target,
    header: &str,
) -> Option<(String, String)> {
    let lib = program.library.as_ref()?;
    let prefix = prefix(lib);
    let mut out = String::from(header);
    let (include, declare, lock, unlock) = c::lock(target, "lock");
    let _ = write!(out, "#include \"program.h\"\n{include}");
    if lib.ownership.is_some() {
        out.push_str("#include <string.h>\n");
    }
    out.push_str(&fill(
        &LIBRARY_HEAD,
        &[
            ("name", &c::comment(&lib.name)),
            ("declare", &declare),
            ("count", &lib.attributes.len()),
        ],
    ));
    let global = |i: usize| {
        let at = AttributeId::new(i);
        lib.ownership
            .as_ref()
            .and_then(|o| o.global.iter().position(|g| g.at == at))
    };
    if let Some(ownership) = &lib.ownership {
        owner_protocol(&mut out, program, peers, lib, ownership, &lock, &unlock);
    }
    for (i, key) in lib.attributes.iter().enumerate() {
        let _ = writeln!(out, "/* {} */", c::comment(key));
        match global(i) {
            None => {
                out.push_str(&fill(
                    &LOCAL_VALUE,
                    &[
                        ("prefix", &prefix),
                        ("getter", &getter(key)),
                        ("setter", &setter(key)),
                        ("i", &i),
                        ("lock", &lock),
                        ("unlock", &unlock),
                    ],
                ));
            }
            Some(k) => {
                out.push_str(&fill(
                    &GLOBAL_VALUE,
                    &[
                        ("prefix", &prefix),
                        ("getter", &getter(key)),
                        ("setter", &setter(key)),
                        ("key", &c::string(key)),
                        ("i", &i),
                        ("k", &k),
                        ("lock", &lock),
                        ("unlock", &unlock),
                    ],
                ));
            }
        }
    }
    if lib.ownership.is_some() {
        // A value taken wakes the control task, which reads it at its next
        // firing (the static schedule fires it at every pass anyway).
        let wake = match target.layer() {
            Layer::Threads => format!("\n        semo_wake({});", c::string(CONTROL_TASK)),
            Layer::Static => String::new(),
        };
        heard(&mut out, &prefix, &lock, &unlock, &wake);
    }
    Some((format!("lib_{prefix}.c"), out))
}

/// The tables of the global values, `current_owner` and `tell`.
fn owner_protocol(
    out: &mut String,
    program: &RobotProgram,
    peers: &Peers,
    lib: &SharedLibrary,
    ownership: &Ownership,
    lock: &str,
    unlock: &str,
) {
    let words = Words::of(program);
    let list = |items: &mut dyn Iterator<Item = String>| items.collect::<Vec<_>>().join(", ");
    let global = &ownership.global;
    out.push_str(&fill(
        &GLOBALS,
        &[
            ("at", &list(&mut global.iter().map(|g| g.at.to_string()))),
            (
                "names",
                &list(&mut global.iter().map(|g| c::string(lib.attribute(g.at)))),
            ),
            (
                "set_keys",
                &list(&mut global.iter().map(|g| c::string(&g.set_key))),
            ),
            (
                "value_keys",
                &list(&mut global.iter().map(|g| c::string(&g.value_key))),
            ),
            (
                "types",
                &list(&mut global.iter().map(|g| g.kind.c_tag().to_string())),
            ),
        ],
    ));
    out.push_str("static const unsigned short *const global_domain[] = {");
    let mut lengths = Vec::new();
    for (n, g) in global.iter().enumerate() {
        let sep = if n == 0 { "" } else { ", " };
        match &g.kind {
            ValueKind::Word(domain) if !domain.is_empty() => {
                let indices: Vec<String> =
                    domain.iter().map(|w| words.index(w).to_string()).collect();
                let _ = write!(
                    out,
                    "{sep}(const unsigned short[]){{{}}}",
                    indices.join(", ")
                );
                lengths.push(domain.len().to_string());
            }
            // `{0}` with length 0: an empty enumeration refuses every word.
            ValueKind::Word(_) => {
                let _ = write!(out, "{sep}(const unsigned short[]){{0}}");
                lengths.push("0".into());
            }
            _ => {
                let _ = write!(out, "{sep}NULL");
                lengths.push("0".into());
            }
        }
    }
    let _ = writeln!(
        out,
        "}};\nstatic const unsigned short global_domain_len[] = {{{}}};\n",
        lengths.join(", ")
    );
    out.push_str(&fill(
        &OWNERS,
        &[
            ("owners", &peers.locals(&ownership.owners)),
            ("first", &peers.local(ownership.owners[0])),
        ],
    ));
    let lost = crate::refine::protocol::lost_after_ms(program.control.heartbeat_ms);
    out.push_str(&fill(
        &TELL,
        &[
            ("name", &c::string(&lib.name)),
            ("follow", &follower(ownership.rule, lost)),
            ("prefix", &prefix(lib)),
            ("lock", &lock),
            ("unlock", &unlock),
            ("lost", &lost),
        ],
    ));
}

/// The loop of `current_owner` choosing who follows a lost owner among the
/// live robots of `owners` (this robot, or heard from within
/// `lost_after_ms`): the first, or by the team's `highest_battery` leader
/// selection the one whose heartbeat said the highest level (the first of
/// equals; unknown counts lowest; this robot's own level in simulation).
fn follower(rule: OwnerRule, lost: i64) -> String {
    let follow = if rule.by_battery() {
        &FOLLOW_BATTERY
    } else {
        &FOLLOW_FIRST
    };
    fill(follow, &[("lost", &lost)])
}

/// `<prefix>_heard`: a write sent to this robot (taken when it owns the
/// value, else refused: the writer's owner is lost or not yet known here)
/// and the owner's values.
fn heard(out: &mut String, prefix: &str, lock: &str, unlock: &str, wake: &str) {
    out.push_str(&fill(
        &HEARD,
        &[
            ("prefix", &prefix),
            ("lock", &lock),
            ("unlock", &unlock),
            ("wake", &wake),
        ],
    ));
}
