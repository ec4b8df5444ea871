//! Fixed text of the generated files (C fragments, Makefiles) kept as files
//! under `codegen/templates/` (compiled in with `include_str!`), with named
//! slots that one function fills: [`fill`].
//!
//! A slot is `{{name}}`, `name` a lower-case identifier (`[a-z_][a-z0-9_]*`);
//! any other `{{` is text (C's `{{0}}` stays as it is). Every template
//! declares its slots ([`Template::slots`]): the test
//! `every_template_declares_exactly_the_slots_it_holds` checks each file
//! against its declaration, and [`fill`] checks that the values given are
//! exactly the declared slots, so that a slot is never left empty nor a
//! value silently unused. The values are text of the generated file's
//! language, already escaped by the caller (`c::string`, `c::comment`, ...).

use std::fmt::{Display, Write};

/// A template file (under `codegen/templates/`, or the runtime's link
/// script) and the slots it holds.
#[derive(Clone, Copy, Debug)]
pub struct Template {
    /// Its path under `codegen/` (`templates/...`; a board's link script is
    /// the runtime's, `runtime/...`).
    pub path: &'static str,
    pub text: &'static str,
    /// Its slots' names, each once, in any order.
    pub slots: &'static [&'static str],
}

/// `template!("dir/file.c.in", ["slot", ...])`: a [`Template`] compiled in.
macro_rules! template {
    ($path:literal, [$($slot:literal),* $(,)?]) => {
        $crate::codegen::template::Template {
            path: concat!("templates/", $path),
            text: include_str!(concat!("templates/", $path)),
            slots: &[$($slot),*],
        }
    };
}
pub(super) use template;

/// A slot found in a template's text: its byte range (braces included) and
/// its name.
fn next_slot(text: &str, from: usize) -> Option<(usize, usize, &str)> {
    let bytes = text.as_bytes();
    let mut at = from;
    while let Some(found) = text[at..].find("{{") {
        let start = at + found;
        let name_start = start + 2;
        let name_len = bytes[name_start..]
            .iter()
            .enumerate()
            .take_while(|&(i, b)| {
                b.is_ascii_lowercase() || *b == b'_' || (i > 0 && b.is_ascii_digit())
            })
            .count();
        let name_end = name_start + name_len;
        if name_len > 0 && text[name_end..].starts_with("}}") {
            return Some((start, name_end + 2, &text[name_start..name_end]));
        }
        at = start + 1;
    }
    None
}

/// The names of the slots `text` holds, in order of appearance, repeated as
/// they appear.
#[cfg(test)]
fn slots_in(text: &str) -> Vec<&str> {
    let mut found = Vec::new();
    let mut at = 0;
    while let Some((_, end, name)) = next_slot(text, at) {
        found.push(name);
        at = end;
    }
    found
}

/// `template`'s text with every slot replaced by its value in `values`
/// (`(name, value)`). The values must name exactly the template's declared
/// slots: a slot without a value, or a value for no slot, is a mistake of
/// the generator, not of its input, and stops it here (the golden test
/// fills every template).
pub fn fill(template: &Template, values: &[(&str, &dyn Display)]) -> String {
    for (name, _) in values {
        assert!(
            template.slots.contains(name),
            "internal error: template {} has no slot `{name}`",
            template.path
        );
    }
    for slot in template.slots {
        assert!(
            values.iter().filter(|(name, _)| name == slot).count() == 1,
            "internal error: template {}: slot `{slot}` needs one value",
            template.path
        );
    }
    let text = template.text;
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    while let Some((start, end, name)) = next_slot(text, at) {
        out.push_str(&text[at..start]);
        let value = values
            .iter()
            .find(|(slot, _)| *slot == name)
            .map(|(_, value)| value)
            .unwrap_or_else(|| {
                panic!(
                    "internal error: template {} holds slot `{name}` it does not declare",
                    template.path
                )
            });
        let _ = write!(out, "{value}");
        at = end;
    }
    out.push_str(&text[at..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const GREETING: Template = Template {
        path: "test/greeting.c.in",
        text: "static const char *who = {{who}}; /* {{why}} */\nint a[1][1] = {{0}};\n{{{who}}}",
        slots: &["who", "why"],
    };

    #[test]
    fn fills_each_slot_with_its_value_and_leaves_other_braces() {
        let filled = fill(&GREETING, &[("who", &"\"you\""), ("why", &3)]);
        assert_eq!(
            filled,
            "static const char *who = \"you\"; /* 3 */\nint a[1][1] = {{0}};\n{\"you\"}"
        );
    }

    #[test]
    fn finds_slots_in_order() {
        assert_eq!(slots_in(GREETING.text), ["who", "why", "who"]);
        assert_eq!(slots_in("{{a1}} {{1a}} {{A}} {{ a }} {{b_c}"), ["a1"]);
    }

    #[test]
    #[should_panic(expected = "slot `why` needs one value")]
    fn a_slot_without_a_value_is_an_internal_error() {
        fill(&GREETING, &[("who", &"x")]);
    }

    #[test]
    #[should_panic(expected = "has no slot `whom`")]
    fn a_value_for_no_slot_is_an_internal_error() {
        fill(&GREETING, &[("who", &"x"), ("why", &"y"), ("whom", &"z")]);
    }

    #[test]
    fn every_template_declares_exactly_the_slots_it_holds() {
        for template in crate::codegen::all_templates() {
            let mut held = slots_in(template.text);
            held.sort_unstable();
            held.dedup();
            let mut declared = template.slots.to_vec();
            declared.sort_unstable();
            assert_eq!(held, declared, "template {}", template.path);
        }
    }

    #[test]
    fn every_file_under_templates_is_a_template() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/codegen/templates");
        let mut files = Vec::new();
        let mut folders = vec![root.clone()];
        while let Some(folder) = folders.pop() {
            for entry in std::fs::read_dir(&folder).into_iter().flatten().flatten() {
                let path = entry.path();
                if path.is_dir() {
                    folders.push(path);
                } else {
                    let relative = path.strip_prefix(&root).unwrap();
                    files.push(relative.to_string_lossy().replace('\\', "/"));
                }
            }
        }
        files.sort();
        let mut listed: Vec<String> = crate::codegen::all_templates()
            .filter_map(|t| t.path.strip_prefix("templates/"))
            .map(str::to_string)
            .collect();
        listed.sort();
        assert_eq!(
            files, listed,
            "files under codegen/templates/ and template::crate::codegen::all_templates()"
        );
    }
}
