use super::*;
use crate::diag::Severity;
use proptest::prelude::*;

const FILE: FileId = FileId(7);

const VALID: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<Catalog xmlns="urn:semo:catalog:1">
  <Robot type="Turtlebot3_Burger" aliases="TurtlebotBurger">
    <Doc>TurtleBot3 Burger: Raspberry Pi 3 (Linux)
         plus an OpenCR micro-controller.</Doc>
    <Platform os="linux" cpu="ARM Cortex-A53" cores="4" clockMHz="1400" memoryKB="1048576"/>
    <Capability name="wheels"/>
    <Capability name="led"/>
    <Value name="LIGHTNESS" type="int" unit="lux" task="light" doc="Ambient light level."/>
    <Value name="COLOR" type="enum" domain="RED GREEN BLUE NONE" task="color" doc="Floor color."/>
    <Service name="move" graph="graphs/move_lds.taskgraph.xml" doc="Drive to a goal.">
      <Param name="goal" type="location" optional="true"/>
    </Service>
    <Service name="light_on" task="led" doc="Switch the LED on &amp; wait."/>
  </Robot>
  <Robot type="MyBot">
    <Value name="X" type="float" aliases="ex why" doc="x"/>
  </Robot>
</Catalog>
"#;

fn parse(text: &str) -> ParsedCatalog {
    parse_catalog(FILE, text, None)
}

fn codes(text: &str) -> Vec<&'static str> {
    parse(text)
        .diagnostics
        .iter()
        .map(|d| d.code.as_str())
        .collect()
}

/// The text that the only diagnostic points at.
fn only(text: &str) -> (Diagnostic, &str) {
    let parsed = parse(text);
    assert_eq!(parsed.diagnostics.len(), 1, "{:#?}", parsed.diagnostics);
    let d = parsed.diagnostics.into_iter().next().unwrap();
    let at = &text[d.span.range()];
    (d, at)
}

fn wrap(robot_body: &str) -> String {
    format!("<Catalog>\n<Robot type=\"R\">\n{robot_body}\n</Robot>\n</Catalog>\n")
}

#[test]
fn valid_file() {
    let parsed = parse(VALID);
    assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
    assert!(parsed.operator.is_none());
    let robots: Vec<&RobotType> = parsed.robots.iter().map(|r| &r.robot).collect();
    assert_eq!(robots.len(), 2);
    let burger = robots[0];
    assert_eq!(burger.name, "Turtlebot3_Burger");
    assert_eq!(burger.aliases, ["TurtlebotBurger"]);
    assert_eq!(
        burger.doc,
        "TurtleBot3 Burger: Raspberry Pi 3 (Linux) plus an OpenCR micro-controller."
    );
    assert_eq!(burger.platform.os, "linux");
    assert_eq!(burger.platform.cpu, "ARM Cortex-A53");
    assert_eq!(burger.platform.cores, Some(4));
    assert_eq!(burger.platform.clock_mhz, Some(1400));
    assert_eq!(burger.platform.memory_kb, Some(1_048_576));
    assert_eq!(burger.capabilities, ["wheels", "led"]);
    let color = burger.value("COLOR").unwrap();
    assert_eq!(
        color.ty,
        ValueType::Enum(vec![
            "RED".into(),
            "GREEN".into(),
            "BLUE".into(),
            "NONE".into()
        ])
    );
    assert_eq!(color.implementation, Implementation::Task("color".into()));
    assert_eq!(
        burger.value("LIGHTNESS").unwrap().unit.as_deref(),
        Some("lux")
    );
    let mv = burger.service("move").unwrap();
    assert_eq!(mv.signature(), "move(goal?: location)");
    assert_eq!(
        mv.implementation,
        Implementation::Graph("graphs/move_lds.taskgraph.xml".into())
    );
    assert_eq!(
        burger.service("light_on").unwrap().doc,
        "Switch the LED on & wait."
    );
    let x = robots[1].value("why").unwrap();
    assert_eq!(x.aliases, ["ex", "why"]);
    assert_eq!(x.ty, ValueType::Float);
    assert_eq!(parsed.robots[0].names[1].0, "TurtlebotBurger");
    assert_eq!(
        &VALID[parsed.robots[0].names[1].1.range()],
        "TurtlebotBurger"
    );
}

#[test]
fn origins_span_start_tags() {
    let parsed = parse(VALID);
    let burger = &parsed.robots[0].robot;
    assert_eq!(burger.origin.file, FILE);
    assert_eq!(
        &VALID[burger.origin.span.range()],
        r#"<Robot type="Turtlebot3_Burger" aliases="TurtlebotBurger">"#
    );
    let mv = burger.service("move").unwrap();
    assert_eq!(
        &VALID[mv.origin.span.range()],
        r#"<Service name="move" graph="graphs/move_lds.taskgraph.xml" doc="Drive to a goal.">"#
    );
    let light = burger.value("LIGHTNESS").unwrap();
    assert_eq!(
        &VALID[light.origin.span.range()],
        r#"<Value name="LIGHTNESS" type="int" unit="lux" task="light" doc="Ambient light level."/>"#
    );
}

#[test]
fn operator_is_not_a_robot() {
    let text = r#"<Catalog><Operator type="USER" aliases="user"><Doc>Console</Doc>
        <Value name="RC_CMD" type="string" aliases="cmd" doc="Command"/></Operator></Catalog>"#;
    let parsed = parse(text);
    assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
    assert!(parsed.robots.is_empty());
    let user = parsed.operator.unwrap().robot;
    assert_eq!(user.name, "USER");
    assert_eq!(user.value("cmd").unwrap().name, "RC_CMD");
    let (robots, diags) = parse_catalog_file(FILE, text, None);
    assert!(robots.is_empty() && diags.is_empty());

    let (d, at) = only(r#"<Catalog><Operator type="Console"/></Catalog>"#);
    assert_eq!(d.code, Code::CatalogBadAttribute);
    assert_eq!(at, "Console");
}

#[test]
fn malformed_mismatched_tag() {
    let text = "<Catalog>\n<Robot type=\"A\"/>\n<Robot type=\"B\">\n</Value>\n</Catalog>";
    let parsed = parse(text);
    assert_eq!(parsed.diagnostics.len(), 1, "{:#?}", parsed.diagnostics);
    let d = &parsed.diagnostics[0];
    assert_eq!(d.code, Code::CatalogXml);
    assert_eq!(&text[d.span.range()], "</Value>");
    assert_eq!(d.related.len(), 1);
    assert_eq!(&text[d.related[0].span.range()], "<Robot type=\"B\">");
    // The robot completed before the error is kept, the open one is not.
    let names: Vec<&str> = parsed
        .robots
        .iter()
        .map(|r| r.robot.name.as_str())
        .collect();
    assert_eq!(names, ["A"]);
}

#[test]
fn malformed_unclosed_element() {
    let text = "<Catalog>\n<Robot type=\"A\">\n";
    let (d, at) = only(text);
    assert_eq!(d.code, Code::CatalogXml);
    assert_eq!(at, "<Robot type=\"A\">");
    assert!(d.message.contains("never closed"), "{}", d.message);
}

#[test]
fn malformed_unclosed_tag() {
    let text = "<Catalog>\n<Robot type=\"A\"/>\n<Robot type=\"B\"";
    let parsed = parse(text);
    assert_eq!(codes(text), ["E050"]);
    let d = &parsed.diagnostics[0];
    assert!(text[d.span.range()].starts_with("<Robot"), "{:?}", d.span);
    assert_eq!(parsed.robots.len(), 1);
}

#[test]
fn malformed_lt_in_attribute() {
    let text = "<Catalog>\n<Robot type=\"A<B\"/>\n</Catalog>";
    let (d, at) = only(text);
    assert_eq!(d.code, Code::CatalogXml);
    assert_eq!(at, "<");
    assert_eq!(d.span.start, text.find("A<B").unwrap() + 1);
}

#[test]
fn malformed_garbage() {
    let (d, at) = only("hello <Catalog/>");
    assert_eq!(d.code, Code::CatalogXml);
    assert_eq!(at, "hello");
    let (d, _) = only("<Catalog/>\n<Catalog/>");
    assert_eq!(d.code, Code::CatalogXml);
    let (d, _) = only("   ");
    assert_eq!(d.code, Code::CatalogXml);
    let (d, _) = only("");
    assert_eq!(d.code, Code::CatalogXml);
    let (d, at) = only("<Catalog><Robot type=\"A\" aliases=B/></Catalog>");
    assert_eq!(d.code, Code::CatalogXml);
    assert!(at.starts_with('B'), "{at}");
    let (d, _) = only("<Catalog><Robot type=\"A\" type=\"B\"/></Catalog>");
    assert_eq!(d.code, Code::CatalogXml);
    let (d, at) = only("<Catalog><Robot type=\"A&bogus;\"/></Catalog>");
    assert_eq!(d.code, Code::CatalogXml);
    assert_eq!(at, "A&bogus;");
    let (d, at) = only("<Catalog><Robot type=\"A\"><Doc>a &nope; b</Doc></Robot></Catalog>");
    assert_eq!(d.code, Code::CatalogXml);
    assert_eq!(at, "&nope;");
    let (d, _) = only("<Catalog></Catalog></Catalog>");
    assert_eq!(d.code, Code::CatalogXml);
    let (d, _) = only("<Catalog><!-- unclosed </Catalog>");
    assert_eq!(d.code, Code::CatalogXml);
    let (d, _) = only("<Catalog>< Robot/></Catalog>");
    assert_eq!(d.code, Code::CatalogXml);
}

#[test]
fn doc_entities_and_cdata() {
    let text =
        "<Catalog><Robot type=\"A\"><Doc>a &lt; b &#65; <![CDATA[<c>]]></Doc></Robot></Catalog>";
    let parsed = parse(text);
    assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
    assert_eq!(parsed.robots[0].robot.doc, "a < b A <c>");
}

#[test]
fn doc_text_is_read_as_written_around_comments_and_stray_elements() {
    // Comments join words; whitespace and a blank reference separate them; an
    // element inside `<Doc>` is reported and its place joins words.
    let text =
        "<Catalog><Robot type=\"A\"><Doc>a<!-- c -->b &#32;c<X>no</X>d</Doc></Robot></Catalog>";
    let parsed = parse(text);
    assert_eq!(codes(text), ["E051"]);
    assert_eq!(&text[parsed.diagnostics[0].span.range()], "X");
    assert_eq!(parsed.robots[0].robot.doc, "ab cd");
}

#[test]
fn unknown_element() {
    let text = wrap("<Valeu name=\"X\" type=\"int\"/>");
    let (d, at) = only(&text);
    assert_eq!(d.code, Code::CatalogUnknownElement);
    assert_eq!(at, "Valeu");
    assert_eq!(d.suggestion.as_deref(), Some("Value"));

    // A known element in the wrong place.
    let text = wrap("<Param name=\"x\" type=\"int\"/>");
    let (d, at) = only(&text);
    assert_eq!(d.code, Code::CatalogUnknownElement);
    assert_eq!(at, "Param");
    assert!(d.message.contains("inside `<Service>`"), "{}", d.message);

    // The content of an unknown element is skipped silently.
    let text = wrap("<Extra><Foo/><Bar>text</Bar></Extra>");
    assert_eq!(codes(&text), ["E051"]);

    let (d, at) = only("<Robots><Robot type=\"A\"/></Robots>");
    assert_eq!(d.code, Code::CatalogUnknownElement);
    assert_eq!(at, "Robots");

    let text = wrap("stray words");
    let (d, at) = only(&text);
    assert_eq!(d.code, Code::CatalogUnknownElement);
    assert_eq!(at, "stray words");
}

#[test]
fn missing_attributes() {
    for (body, attr, tag) in [
        ("<Value type=\"int\"/>", "name", "<Value type=\"int\"/>"),
        ("<Value name=\"X\"/>", "type", "<Value name=\"X\"/>"),
        ("<Service doc=\"d\"/>", "name", "<Service doc=\"d\"/>"),
        ("<Capability/>", "name", "<Capability/>"),
        (
            "<Service name=\"s\"><Param type=\"int\"/></Service>",
            "name",
            "<Param type=\"int\"/>",
        ),
        (
            "<Service name=\"s\"><Param name=\"p\"/></Service>",
            "type",
            "<Param name=\"p\"/>",
        ),
    ] {
        let text = wrap(body);
        let (d, at) = only(&text);
        assert_eq!(d.code, Code::CatalogMissingAttribute, "{body}");
        assert_eq!(at, tag);
        assert!(d.message.contains(&format!("`{attr}`")), "{}", d.message);
    }
    let text = "<Catalog>\n  <Robot aliases=\"x\">\n    <Value name=\"A\" type=\"int\"/>\n  </Robot>\n</Catalog>";
    let parsed = parse(text);
    assert_eq!(parsed.diagnostics.len(), 1);
    assert_eq!(parsed.diagnostics[0].code, Code::CatalogMissingAttribute);
    assert_eq!(
        &text[parsed.diagnostics[0].span.range()],
        "<Robot aliases=\"x\">"
    );
    assert!(parsed.robots.is_empty());
}

#[test]
fn duplicates() {
    let text = "<Catalog>\n<Robot type=\"A\" aliases=\"a\"/>\n<Robot type=\"A\"/>\n<Robot type=\"B\" aliases=\"a b2\"/>\n</Catalog>";
    let parsed = parse(text);
    let diags = &parsed.diagnostics;
    assert_eq!(diags.len(), 2, "{diags:#?}");
    assert!(diags.iter().all(|d| d.code == Code::CatalogDuplicateType));
    assert_eq!(diags[0].span.start, text.find("\"A\"/>").unwrap() + 1);
    assert_eq!(&text[diags[0].related[0].span.range()], "A");
    assert_eq!(
        diags[0].related[0].span.start,
        text.find("\"A\"").unwrap() + 1
    );
    assert_eq!(&text[diags[1].span.range()], "a");
    assert_eq!(&text[diags[1].related[0].span.range()], "a");
    let robots: Vec<(&str, &[String])> = parsed
        .robots
        .iter()
        .map(|r| (r.robot.name.as_str(), r.robot.aliases.as_slice()))
        .collect();
    assert_eq!(robots.len(), 2);
    assert_eq!(robots[1], ("B", &["b2".to_string()][..]));

    let text = wrap(
        "<Value name=\"X\" type=\"int\"/>\n<Value name=\"X\" type=\"bool\"/>\n<Service name=\"s\"/>\n<Service name=\"t\" aliases=\"s\"/>",
    );
    let parsed = parse(&text);
    assert_eq!(
        parsed
            .diagnostics
            .iter()
            .map(|d| d.code)
            .collect::<Vec<_>>(),
        [Code::CatalogDuplicateType, Code::CatalogDuplicateType]
    );
    let robot = &parsed.robots[0].robot;
    assert_eq!(robot.values.len(), 1);
    assert_eq!(robot.values[0].ty, ValueType::Int);
    assert_eq!(robot.services.len(), 2);
    assert!(robot.services[1].aliases.is_empty());

    let text = wrap(
        "<Service name=\"s\"><Param name=\"p\" type=\"int\"/><Param name=\"p\" type=\"int\"/></Service>",
    );
    assert_eq!(codes(&text), ["E053"]);
    let text = wrap("<Platform os=\"a\"/><Platform os=\"b\"/>");
    assert_eq!(codes(&text), ["E053"]);
    let text = wrap("<Doc>a</Doc><Doc>b</Doc>");
    assert_eq!(codes(&text), ["E053"]);
}

#[test]
fn unknown_types() {
    let text = wrap("<Value name=\"X\" type=\"integer\"/>");
    let (d, at) = only(&text);
    assert_eq!(d.code, Code::CatalogUnknownValueType);
    assert_eq!(at, "integer");
    assert_eq!(d.suggestion.as_deref(), Some("int"));
    let text = wrap("<Value name=\"X\" type=\"strng\"/>");
    let (d, _) = only(&text);
    assert_eq!(d.suggestion.as_deref(), Some("string"));
    let text = wrap("<Service name=\"s\"><Param name=\"p\" type=\"Location\"/></Service>");
    let (d, at) = only(&text);
    assert_eq!(d.code, Code::CatalogUnknownValueType);
    assert_eq!(at, "Location");
    assert_eq!(d.suggestion.as_deref(), Some("location"));
}

#[test]
fn missing_graph() {
    let dir = std::env::temp_dir().join(format!("semo-catalog-test-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("graphs")).unwrap();
    std::fs::write(dir.join("graphs/ok.taskgraph.xml"), "<TaskGraph/>").unwrap();
    let text = wrap(
        "<Service name=\"a\" graph=\"graphs/ok.taskgraph.xml\"/>\n<Service name=\"b\" graph=\"graphs/missing.taskgraph.xml\"/>",
    );
    let parsed = parse_catalog(FILE, &text, Some(&dir));
    assert_eq!(parsed.diagnostics.len(), 1, "{:#?}", parsed.diagnostics);
    let d = &parsed.diagnostics[0];
    assert_eq!(d.code, Code::CatalogMissingGraph);
    assert_eq!(&text[d.span.range()], "graphs/missing.taskgraph.xml");
    assert!(!d.message.contains(dir.to_str().unwrap()));
    // Without a base directory, graphs are not checked.
    assert!(parse(&text).diagnostics.is_empty());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_attribute_values() {
    for (body, at) in [
        ("<Platform cores=\"four\"/>", "four"),
        ("<Platform clockMHz=\"-3\"/>", "-3"),
        ("<Platform memoryKB=\"1 GB\"/>", "1 GB"),
        ("<Value name=\"C\" type=\"enum\"/>", "enum"),
        ("<Value name=\"C\" type=\"enum\" domain=\" \"/>", " "),
        ("<Value name=\"C\" type=\"int\" domain=\"A B\"/>", "A B"),
        ("<Value name=\"C\" type=\"enum\" domain=\"A 2B\"/>", "2B"),
        ("<Value name=\"my value\" type=\"int\"/>", "my value"),
        ("<Value name=\"\" type=\"int\"/>", ""),
        (
            "<Value name=\"V\" type=\"int\" task=\"t\" graph=\"g\"/>",
            "g",
        ),
        ("<Service name=\"s\" aliases=\"ok 9bad\"/>", "9bad"),
        (
            "<Service name=\"s\"><Param name=\"p\" type=\"int\" optional=\"yes\"/></Service>",
            "yes",
        ),
        (
            "<Service name=\"s\"><Param name=\"p\" type=\"int\" optional=\"true\"/><Param name=\"q\" type=\"int\"/></Service>",
            "q",
        ),
    ] {
        let text = wrap(body);
        let (d, got) = only(&text);
        assert_eq!(d.code, Code::CatalogBadAttribute, "{body}: {}", d.message);
        assert_eq!(got, at, "{body}");
    }
    let (d, at) = only("<Catalog><Robot type=\"My Bot\"/></Catalog>");
    assert_eq!(d.code, Code::CatalogBadAttribute);
    assert_eq!(at, "My Bot");
}

#[test]
fn unknown_attributes() {
    let text = wrap("<Value name=\"X\" type=\"int\" colour=\"red\" dco=\"x\"/>");
    let parsed = parse(&text);
    let diags = &parsed.diagnostics;
    assert_eq!(diags.len(), 2);
    assert!(
        diags
            .iter()
            .all(|d| d.code == Code::CatalogUnknownAttribute)
    );
    assert!(diags.iter().all(|d| d.severity == Severity::Warning));
    assert_eq!(&text[diags[0].span.range()], "colour");
    assert_eq!(diags[1].suggestion.as_deref(), Some("doc"));
    // The value itself is kept.
    assert!(parsed.robots[0].robot.value("X").is_some());
    // Namespaces are fine.
    let text = "<c:Catalog xmlns:c=\"urn:semo:catalog:1\" xmlns:xsi=\"x\" xsi:schemaLocation=\"y\"><c:Robot type=\"A\"/></c:Catalog>";
    let parsed = parse(text);
    assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
    assert_eq!(parsed.robots.len(), 1);
}

#[test]
fn alias_spans_with_entities_fall_back_to_whole_value() {
    let text = "<Catalog><Robot type=\"A\" aliases=\"ok &amp;bad\"/></Catalog>";
    let (d, at) = only(text);
    assert_eq!(d.code, Code::CatalogBadAttribute);
    assert_eq!(at, "ok &amp;bad");
}

/// Checks the invariants that renderers rely on.
fn check_invariants(text: &str) {
    let parsed = parse_catalog(FILE, text, Some(Path::new("/nonexistent-semo-dir")));
    for d in &parsed.diagnostics {
        assert!(
            d.span.start <= d.span.end && d.span.end <= text.len(),
            "{d:?}"
        );
        assert!(text.is_char_boundary(d.span.start) && text.is_char_boundary(d.span.end));
        assert!(!d.message.is_empty());
        for r in &d.related {
            assert!(r.span.start <= r.span.end && r.span.end <= text.len());
        }
    }
    for r in parsed.robots.iter().chain(&parsed.operator) {
        let span = r.robot.origin.span;
        assert!(span.start <= span.end && span.end <= text.len());
        assert!(!r.robot.name.is_empty());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn never_panics_on_mutations(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..4), 1..8)
    ) {
        let mut bytes = VALID.as_bytes().to_vec();
        for (index, byte, op) in edits {
            if bytes.is_empty() {
                bytes.push(byte);
                continue;
            }
            let i = index.index(bytes.len());
            let byte = match byte % 8 {
                0 => b'<',
                1 => b'>',
                2 => b'"',
                3 => b'/',
                4 => b'&',
                _ => byte,
            };
            match op {
                0 => bytes[i] = byte,
                1 => bytes.insert(i, byte),
                2 => { bytes.remove(i); }
                _ => { let end = (i + 1 + byte as usize % 40).min(bytes.len()); bytes.drain(i..end); }
            }
        }
        let text = String::from_utf8_lossy(&bytes);
        check_invariants(&text);
    }

    #[test]
    fn never_panics_on_arbitrary_text(text in "[<>/=\"'&;a-zA-Z: \n!?\\-\\[\\]é]{0,200}") {
        check_invariants(&text);
    }
}

#[test]
fn a_platform_names_the_target_its_programs_are_built_for() {
    use crate::platform::Target;
    let text = wrap("<Platform os=\"none\" target=\" cortex-m \"/>");
    let parsed = parse(&text);
    assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
    let (target, span) = parsed.robots[0].robot.platform.target.expect("a target");
    assert_eq!(target, Target::CortexM);
    assert_eq!(&text[span.range()], "cortex-m");
    // Not said: none (the build's default decides).
    let parsed = parse(&wrap("<Platform os=\"linux\"/>"));
    assert_eq!(parsed.robots[0].robot.platform.target, None);
}

#[test]
fn a_platform_target_that_is_no_platform_is_positioned_with_a_did_you_mean() {
    let text = wrap("<Platform target=\"cortx-m\"/>");
    let (d, at) = only(&text);
    assert_eq!((d.code, at), (Code::CatalogBadAttribute, "cortx-m"));
    assert_eq!(
        d.message,
        "unknown platform `cortx-m` (platforms: linux, cortex-m, stm32f4) (did you mean `cortex-m`?)"
    );
    assert_eq!(d.suggestion.as_deref(), Some("cortex-m"));
    // A simulation is the build's choice, not the robot's.
    let text = wrap("<Platform target=\"linux-sim\"/>");
    let (d, at) = only(&text);
    assert_eq!((d.code, at), (Code::CatalogBadAttribute, "linux-sim"));
    assert!(
        d.message.contains("simulation of linux") && d.message.contains("--sim"),
        "{}",
        d.message
    );
}

#[test]
fn latency_bounds_are_read_on_graph_services() {
    let text = wrap(
        "<Service name=\"follow\" graph=\"g.taskgraph.xml\">\n  <Latency from=\" camera \" to=\"wheels\" max=\"0.5 SEC\"/>\n</Service>",
    );
    let parsed = parse(&text);
    assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
    let bounds = &parsed.robots[0].robot.services[0].latency;
    assert_eq!(bounds.len(), 1);
    let bound = &bounds[0];
    assert_eq!(bound.from.0, "camera");
    assert_eq!(&text[bound.from.1.range()], "camera");
    assert_eq!(&text[bound.to.1.range()], "wheels");
    assert_eq!((bound.max.num, bound.max.den), (500, 1));
    assert_eq!(bound.max.written, "0.5 SEC");
    assert!(text[bound.span.range()].starts_with("<Latency"));
}

#[test]
fn bad_latency_bounds_are_positioned() {
    let graph = |latency: &str| {
        wrap(&format!(
            "<Service name=\"follow\" graph=\"g.taskgraph.xml\">{latency}</Service>"
        ))
    };
    for (latency, code, at, says) in [
        (
            "<Latency from=\"a\" to=\"b\" max=\"-5 MSEC\"/>",
            Code::CatalogBadAttribute,
            "-5 MSEC",
            "a positive number (like 50 or 0.5), not `-5`",
        ),
        (
            "<Latency from=\"a\" to=\"b\" max=\"50ms\"/>",
            Code::CatalogBadAttribute,
            "50ms",
            "a positive number and a unit",
        ),
        (
            "<Latency from=\"a\" to=\"b\" max=\"5 DAYS\"/>",
            Code::CatalogBadAttribute,
            "5 DAYS",
            "`DAYS` is not a unit of time",
        ),
        (
            "<Latency from=\"a\" to=\"b\" max=\"0 SEC\"/>",
            Code::CatalogBadAttribute,
            "0 SEC",
            "more than 0",
        ),
        (
            "<Latency from=\"a\" max=\"5 MSEC\"/>",
            Code::CatalogMissingAttribute,
            "<Latency from=\"a\" max=\"5 MSEC\"/>",
            "needs a `to` attribute",
        ),
        (
            "<Latency from=\"\" to=\"b\" max=\"5 MSEC\"/>",
            Code::CatalogBadAttribute,
            "",
            "`from` is empty",
        ),
    ] {
        let text = graph(latency);
        let parsed = parse(&text);
        assert_eq!(
            parsed.diagnostics.len(),
            1,
            "{latency}: {:#?}",
            parsed.diagnostics
        );
        let d = &parsed.diagnostics[0];
        assert_eq!(d.code, code, "{latency}");
        if !at.is_empty() {
            assert_eq!(&text[d.span.range()], at, "{latency}");
        }
        assert!(d.message.contains(says), "{latency}: {}", d.message);
        // A bound with a bad value is left out.
        assert!(parsed.robots[0].robot.services[0].latency.is_empty());
    }
    // On a service that is no graph, and outside a service.
    let text = wrap(
        "<Service name=\"beep\" task=\"buzzer\"><Latency from=\"a\" to=\"b\" max=\"5 MSEC\"/></Service>",
    );
    let (d, at) = only(&text);
    assert_eq!(d.code, Code::CatalogBadAttribute);
    assert!(at.starts_with("<Latency"));
    assert!(
        d.message.contains("`beep` is not implemented by one"),
        "{}",
        d.message
    );
    let text = wrap("<Latency from=\"a\" to=\"b\" max=\"5 MSEC\"/>");
    assert_eq!(codes(&text), ["E051"]);
}

#[test]
fn a_service_lists_its_results_in_order_each_checked_as_a_value() {
    let text = wrap(
        "<Service name=\"survey\" task=\"drill\">\
           <Param name=\"where\" type=\"location\"/>\
           <Result name=\"FOUND\" type=\"bool\" doc=\"Whether it is there.\"/>\
           <Result name=\"GRADE\" type=\"enum\" domain=\"LOW HIGH\"/>\
         </Service>",
    );
    let parsed = parse(&text);
    assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
    let survey = &parsed.robots[0].robot.services[0];
    let results: Vec<(&str, &ValueType, &str)> = survey
        .results
        .iter()
        .map(|r| (r.name.as_str(), &r.ty, r.doc.as_str()))
        .collect();
    let grade = ValueType::Enum(vec!["LOW".into(), "HIGH".into()]);
    assert_eq!(
        results,
        [
            ("FOUND", &ValueType::Bool, "Whether it is there."),
            ("GRADE", &grade, "")
        ]
    );
    assert_eq!(
        survey.results_signature(),
        "FOUND: bool, GRADE: enum {LOW, HIGH}"
    );

    let service = |results: &str| wrap(&format!("<Service name=\"s\">{results}</Service>"));
    let twice = service("<Result name=\"F\" type=\"bool\"/><Result name=\"F\" type=\"int\"/>");
    assert_eq!(codes(&twice), ["E053"]);
    assert_eq!(
        codes(&service("<Result name=\"a b\" type=\"bool\"/>")),
        ["E056"]
    );
    assert_eq!(
        codes(&service("<Result name=\"F\" type=\"boolean\"/>")),
        ["E054"]
    );
    assert_eq!(codes(&service("<Result name=\"F\"/>")), ["E052"]);
    assert_eq!(
        codes(&service("<Result name=\"F\" type=\"enum\"/>")),
        ["E056"]
    );
    assert_eq!(codes(&wrap("<Result name=\"F\" type=\"bool\"/>")), ["E051"]);
}

proptest! {
    /// A doc collapsed to one line has the words `split_whitespace` finds,
    /// one space apart, whichever split reads it (vertical tabs and Unicode
    /// spaces included).
    #[test]
    fn one_line_keeps_the_words_of_split_whitespace(s in "[a-c \t\n\r\u{b}\u{c}\u{a0}\u{2003}]{0,24}") {
        let words: Vec<&str> = s.split_whitespace().collect();
        prop_assert_eq!(one_line(&s), words.join(" "));
    }
}
