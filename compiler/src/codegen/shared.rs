//! The library task `lib_<name>.c`: the team's shared information, and for
//! its globally shared values the owner protocol of
//! `docs/shared-information.md` (refinement's `Ownership`): one robot of the
//! team owns them; a write elsewhere goes to the owner (`Team.__set.X`), the
//! owner tells the team every value it takes (`Team.__value.X`), and the
//! first live robot of the owner order takes over from a lost owner (no
//! heartbeat for three periods), telling the team the values it last saw.
//! The simulator does the same (`sim/engine/shared.rs`).

use super::c;
use super::files::lock;
use super::peers::Peers;
use super::values::Words;
use super::{Layer, Target};
use crate::refine::graph::{CONTROL_TASK, getter, setter};
use crate::refine::{OwnerRule, Ownership, RobotProgram, SharedLibrary, ValueKind};
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
        let _ = writeln!(
            out,
            "/* A message of the owner protocol (comm_task.c hands each message over):\n * true when it was one, taken. */\nbool {prefix}_heard(const semo_message *m);\n/* When this robot would find its owner lost (mission ms; INT64_MAX while it\n * owns the values): the control task fires then. */\nint64_t {prefix}_owner_lost_at(void);"
        );
    }
    out
}

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
    let (include, declare, lock, unlock) = lock(target, "lock");
    let _ = write!(out, "#include \"program.h\"\n{include}");
    if lib.ownership.is_some() {
        out.push_str("#include <string.h>\n");
    }
    let _ = writeln!(
        out,
        "\n/* Library task {}: the team's shared information, one value per attribute,\n * read and written by its getters and setters under one lock. */\n{declare}static semo_value value[{}];\n",
        c::comment(&lib.name),
        lib.attributes.len()
    );
    let global = |i: usize| {
        lib.ownership
            .as_ref()
            .and_then(|o| o.global.iter().position(|g| g.at == i))
    };
    if let Some(ownership) = &lib.ownership {
        owner_protocol(&mut out, program, peers, lib, ownership, &lock, &unlock);
    }
    for (i, key) in lib.attributes.iter().enumerate() {
        let _ = writeln!(out, "/* {} */", c::comment(key));
        match global(i) {
            None => {
                let _ = writeln!(
                    out,
                    "LIBFUNC(semo_value, {prefix}_{}, (void))\n{{\n    {lock}\n    semo_value v = value[{i}];\n    {unlock}\n    return v;\n}}\n\nLIBFUNC(void, {prefix}_{}, (const semo_value *v))\n{{\n    {lock}\n    value[{i}] = *v;\n    {unlock}\n}}\n",
                    getter(key),
                    setter(key)
                );
            }
            Some(k) => {
                let _ = writeln!(
                    out,
                    "LIBFUNC(semo_value, {prefix}_{}, (void))\n{{\n    current_owner();\n    {lock}\n    semo_value v = value[{i}];\n    {unlock}\n    return v;\n}}\n\nLIBFUNC(void, {prefix}_{}, (const semo_value *v))\n{{\n    size_t to = current_owner();\n    {lock}\n    value[{i}] = *v;\n    {unlock}\n    semo_trace_value(\"shared_set\", \"value\", v, \"key\", {key_c}, \"owner\", semo_program()->peers[to].robot, NULL);\n    tell({k}, to, v);\n}}\n",
                    getter(key),
                    setter(key),
                    key_c = c::string(key),
                );
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
    let _ = writeln!(
        out,
        "/* Globally shared values (docs/shared-information.md): the owner holds\n * them; a write elsewhere is sent to it (`set`), and it tells the team each\n * value it takes (`told`). Per global value: its place in `value`, the keys,\n * its type and an enumeration's words (a value of another type is refused). */\nstatic const size_t global_at[] = {{{}}};\nstatic const char *const global_key[] = {{{}}};\nstatic const char *const set_key[] = {{{}}};\nstatic const char *const told_key[] = {{{}}};\nstatic const semo_type global_type[] = {{{}}};",
        list(&mut global.iter().map(|g| g.at.to_string())),
        list(&mut global.iter().map(|g| c::string(&lib.attributes[g.at]))),
        list(&mut global.iter().map(|g| c::string(&g.set_key))),
        list(&mut global.iter().map(|g| c::string(&g.value_key))),
        list(&mut global.iter().map(|g| g.kind.c_tag().to_string())),
    );
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
    let _ = writeln!(
        out,
        "/* The robots that own the values in turn (peer indices) and the owner now. */\nstatic const size_t owners[] = {{{}}};\nstatic size_t owner = {};\n",
        peers.locals(&ownership.owners),
        peers.local(ownership.owners[0])
    );
    let hb = program.control.heartbeat_ms;
    let _ = writeln!(
        out,
        "/* Tells the owner `to` of a write of global value `k`, or the team when\n * this robot owns it. */\nstatic void tell(size_t k, size_t to, const semo_value *v)\n{{\n    const semo_program_desc *p = semo_program();\n    if (to == p->self)\n        semo_comm_send(p->team, SEMO_MSG_SEND, told_key[k], v);\n    else\n        semo_comm_send(p->peers[to].robot, SEMO_MSG_SEND, set_key[k], v);\n}}\n\n/* The owner now: the owner stays while it lives (this robot, or heard from\n * within three heartbeats); a lost one is followed by the first live robot\n * of `owners`. A change is traced; a robot that becomes the owner tells the\n * team the values it last saw. */\nstatic size_t current_owner(void)\n{{\n    const semo_program_desc *p = semo_program();\n    int64_t now = semo_now_ms();\n    {lock}\n    size_t was = owner;\n    if (was != p->self && now - comm_heard(was).seen > 3 * {hb}) {{\n{follow}    }}\n    size_t now_owner = owner;\n    {unlock}\n    if (now_owner == was)\n        return was;\n    semo_trace(\"shared_owner\", \"library\", {name}, \"owner\", p->peers[now_owner].robot, \"lost\", p->peers[was].robot, NULL);\n    if (now_owner == p->self)\n        for (size_t k = 0; k < sizeof global_at / sizeof global_at[0]; k++) {{\n            {lock}\n            semo_value v = value[global_at[k]];\n            {unlock}\n            if (v.type != SEMO_NONE)\n                tell(k, now_owner, &v);\n        }}\n    return now_owner;\n}}\n\n/* Three heartbeats after the owner was last heard from, and one ms more:\n * the control task's read_inputs asks then (current_owner), as the\n * simulator's firing does. */\nint64_t {prefix}_owner_lost_at(void)\n{{\n    const semo_program_desc *p = semo_program();\n    {lock}\n    size_t now_owner = owner;\n    {unlock}\n    return now_owner == p->self ? INT64_MAX : comm_heard(now_owner).seen + 3 * {hb} + 1;\n}}\n",
        name = c::string(&lib.name),
        follow = follower(ownership.rule, hb),
        prefix = prefix(lib),
    );
}

/// The loop of `current_owner` choosing who follows a lost owner among the
/// live robots of `owners` (this robot, or heard from within three
/// heartbeats): the first, or by the team's `highest_battery` leader
/// selection the one whose heartbeat said the highest level (the first of
/// equals; unknown counts lowest; this robot's own level in simulation).
fn follower(rule: OwnerRule, hb: i64) -> String {
    if !rule.by_battery() {
        return format!(
            "        for (size_t k = 0; k < sizeof owners / sizeof owners[0]; k++) {{\n            size_t c = owners[k];\n            if (c == p->self || now - comm_heard(c).seen <= 3 * {hb}) {{\n                owner = c;\n                break;\n            }}\n        }}\n"
        );
    }
    format!(
        "        bool found = false;\n        long best = -1;\n        for (size_t k = 0; k < sizeof owners / sizeof owners[0]; k++) {{\n            size_t c = owners[k];\n            comm_heartbeat h = comm_heard(c);\n            if (c != p->self && now - h.seen > 3 * {hb})\n                continue;\n            long level = h.battery;\n            if (c == p->self) {{\n                level = -1;\n#ifdef SEMO_SIM\n                long long own;\n                if (semo_sim_battery(&own))\n                    level = (long)own;\n#endif\n            }}\n            if (!found || level > best) {{\n                owner = c;\n                best = level;\n                found = true;\n            }}\n        }}\n"
    )
}

/// `<prefix>_heard`: a write sent to this robot (taken when it owns the
/// value, else refused: the writer's owner is lost or not yet known here)
/// and the owner's values.
fn heard(out: &mut String, prefix: &str, lock: &str, unlock: &str, wake: &str) {
    let _ = writeln!(
        out,
        "bool {prefix}_heard(const semo_message *m)\n{{\n    for (size_t k = 0; k < sizeof global_at / sizeof global_at[0]; k++) {{\n        bool set = strcmp(m->key, set_key[k]) == 0;\n        if (!set && strcmp(m->key, told_key[k]) != 0)\n            continue;\n        semo_value v = m->value;\n        if (!semo_value_coerce(&v, global_type[k]) || !semo_value_in(&v, global_domain[k], global_domain_len[k])) {{\n            semo_trace(\"reject\", \"key\", m->key, \"reason\", \"not a value of its type\", NULL);\n            return true;\n        }}\n        const semo_program_desc *p = semo_program();\n        if (set) {{\n            size_t to = current_owner();\n            if (to != p->self) {{\n                semo_trace(\"reject\", \"key\", m->key, \"reason\", \"not the owner\", NULL);\n                return true;\n            }}\n            {lock}\n            value[global_at[k]] = v;\n            {unlock}\n            semo_trace_value(\"shared_set\", \"value\", &v, \"key\", global_key[k], \"owner\", p->robot, \"from\", m->from_robot, NULL);\n            tell(k, to, &v);\n        }} else {{\n            {lock}\n            value[global_at[k]] = v;\n            {unlock}\n            semo_trace_value(\"shared_value\", \"value\", &v, \"key\", global_key[k], \"from\", m->from_robot, NULL);\n        }}{wake}\n        return true;\n    }}\n    return false;\n}}"
    );
}
