use super::*;
use proptest::prelude::*;

const FILE: FileId = FileId(3);

const EXAMPLES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/taskgraphs");
const SDF3: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/sdf3");
/// SDF3's benchmarks with actors whose processors are marked
/// `default="true"` twice (W086, their only diagnostics).
const TWO_DEFAULTS: [&str; 4] = [
    "h263decoder.xml",
    "h263encoder.xml",
    "mp3decoder_block_parallelism.xml",
    "mp3decoder_granule_parallelism.xml",
];

/// The diagnostics of an SDF3 benchmark file: none, or W086 alone on the
/// files of [`TWO_DEFAULTS`].
fn assert_benchmark_diagnostics(path: &std::path::Path, diags: &[Diagnostic]) {
    let name = path.file_name().unwrap().to_string_lossy();
    let expected = TWO_DEFAULTS.contains(&name.as_ref());
    assert_eq!(
        !diags.is_empty(),
        expected,
        "{}:\n{}",
        path.display(),
        listing(diags)
    );
    assert!(
        diags
            .iter()
            .all(|d| d.code == Code::Sdf3TwoDefaultProcessors),
        "{}:\n{}",
        path.display(),
        listing(diags)
    );
}

const DATA_LOOP: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/taskgraphs/data_loop.taskgraph.xml"
));
const KMEANS: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/taskgraphs/kmeans.taskgraph.xml"
));
const SHARED_INFO: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../examples/taskgraphs/robot_shared_info.taskgraph.xml"
));
const MODEM: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../tests/data/sdf3/modem.xml"
));
const H263: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../tests/data/sdf3/h263decoder.xml"
));

/// A valid file using every element and attribute of our format.
const VALID: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<TaskGraph name="tld_tracking" xmlns="urn:semo:taskgraph:1">
  <!-- a comment -->
  <Task name="camera" kind="computational" trigger="time" period="33 MSEC" source="tasks/camera.c" wcet="2">
    <Port name="out" dir="out" rate="1" type="image" size="76800"/>
  </Task>
  <Task name="detect" kind="computational" trigger="data" wcet="10" subgraph="detect.taskgraph.xml">
    <Port name="in" dir="in" rate="1"/>
    <Port name="out" dir="out" rate="2"/>
    <Port name="img" dir="out"/>
    <LibraryMasterPort name="shared" library="ColorList" calls="updateColor, allFound">
      <Call function="reset"/>
    </LibraryMasterPort>
    <MulticastPort name="warn" dir="out" group="obstacle_alert"/>
  </Task>
  <Task name="ColorTask" kind="library" trigger="control">
    <LibrarySlavePort name="serve" library="ColorList"/>
  </Task>
  <Library name="ColorList">
    <Function name="updateColor" returns="void"><Param name="color" type="int"/></Function>
    <Function name="allFound" returns="int"/>
    <Function name="reset"/>
  </Library>
  <Loop name="train" type="C" loopCount="100" exitTask="check_err">
    <Port name="images" dir="in" kind="broadcasting" outerRate="2" innerRate="2"/>
    <Port name="model" dir="out" outerRate="1" innerRate="1"/>
    <TaskGraph name="train_body">
      <Task name="check_err"><Port name="i" dir="in" rate="2"/><Port name="o" dir="out"/></Task>
      <Channel src="train.images" dst="check_err.i"/>
      <Channel src="check_err.o" dst="train.model"/>
    </TaskGraph>
  </Loop>
  <Task name="sink"><Port name="i" dir="in"/><Port name="m" dir="in"/></Task>
  <Channel src="camera.out" dst="detect.in" initialTokens="0" capacity="4"/>
  <Channel src="detect.out" dst="train.images" initialTokens="3"/>
  <Channel src="train.model" dst="sink.m"/>
  <Channel src="detect.img" dst="sink.i"/>
</TaskGraph>
"#;

fn load(text: &str) -> (Option<TaskGraph>, Vec<Diagnostic>) {
    let (graph, diags) = load_task_graph(FILE, text);
    check_invariants(text, &diags);
    (graph, diags)
}

fn check_invariants(text: &str, diags: &[Diagnostic]) {
    for d in diags {
        assert_eq!(d.file, FILE);
        assert!(d.span.start <= d.span.end, "{d:?}");
        assert!(d.span.end <= text.len(), "{d:?}");
        assert!(text.is_char_boundary(d.span.start), "{d:?}");
        assert!(text.is_char_boundary(d.span.end), "{d:?}");
        assert!(!d.message.contains('\n'), "{d:?}");
        for r in &d.related {
            assert!(
                r.span.start <= r.span.end && r.span.end <= text.len(),
                "{d:?}"
            );
        }
    }
}

fn codes(text: &str) -> Vec<&'static str> {
    load(text).1.iter().map(|d| d.code.as_str()).collect()
}

/// The one diagnostic of `text`, with the text it points at.
fn only(text: &str) -> (Diagnostic, String) {
    let (_, diags) = load(text);
    assert_eq!(diags.len(), 1, "expected one diagnostic, got {diags:#?}");
    let d = diags.into_iter().next().unwrap();
    let at = text[d.span.range()].to_string();
    (d, at)
}

/// Wraps tasks and channels in a `<TaskGraph>`.
fn wrap(body: &str) -> String {
    format!("<TaskGraph name=\"g\">\n{body}\n</TaskGraph>\n")
}

fn listing(diags: &[Diagnostic]) -> String {
    diags
        .iter()
        .map(|d| format!("{} {:?} {}", d.code, d.span, d.message))
        .collect::<Vec<_>>()
        .join("\n")
}

fn files_in(dir: &str, suffix: &str) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(suffix))
        .collect();
    files.sort();
    files
}

// --- valid files -------------------------------------------------------------

#[test]
fn every_shared_example_loads_cleanly() {
    let files = files_in(EXAMPLES, ".taskgraph.xml");
    assert!(files.len() >= 8, "{files:?}");
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let (graph, diags) = load(&text);
        assert!(diags.is_empty(), "{}:\n{}", path.display(), listing(&diags));
        let graph = graph.unwrap();
        assert!(!graph.tasks.is_empty());
        assert_eq!(detect_format(&text), Some(GraphFormat::SemoXml));
    }
}

#[test]
fn every_sdf3_file_loads_cleanly() {
    let files = files_in(SDF3, ".xml");
    assert_eq!(files.len(), 11);
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let (graph, diags) = load(&text);
        assert_benchmark_diagnostics(&path, &diags);
        let graph = graph.unwrap();
        assert!(!graph.tasks.is_empty());
        assert!(!graph.channels.is_empty());
        // Every channel end resolves, with the right direction.
        for c in &graph.channels {
            let src = graph.tasks[graph.task_index(&c.src.task).unwrap()]
                .port(&c.src.port)
                .unwrap();
            let dst = graph.tasks[graph.task_index(&c.dst.task).unwrap()]
                .port(&c.dst.port)
                .unwrap();
            assert_eq!((src.dir, dst.dir), (Direction::Out, Direction::In));
        }
        assert!(graph.tasks.iter().all(|t| t.wcet.is_some()));
        assert_eq!(detect_format(&text), Some(GraphFormat::Sdf3));
    }
}

#[test]
fn valid_file_uses_every_feature() {
    let (graph, diags) = load(VALID);
    assert!(diags.is_empty(), "{}", listing(&diags));
    let g = graph.unwrap();
    assert_eq!(g.name, "tld_tracking");
    assert_eq!(g.file, FILE);
    assert!(VALID[g.span.range()].starts_with("<TaskGraph"));
    assert!(VALID[g.span.range()].ends_with("</TaskGraph>"));
    let names: Vec<&str> = g.tasks.iter().map(|t| t.name.name.as_str()).collect();
    assert_eq!(names, ["camera", "detect", "ColorTask", "train", "sink"]);

    let camera = &g.tasks[0];
    assert_eq!(camera.trigger, Trigger::Time { period_ms: 33.0 });
    assert_eq!(camera.wcet, Some(2));
    assert_eq!(camera.source.as_deref(), Some("tasks/camera.c"));
    assert_eq!(&VALID[camera.name.span.range()], "camera");
    assert!(VALID[camera.span.range()].starts_with("<Task name=\"camera\""));
    assert!(VALID[camera.span.range()].ends_with("</Task>"));
    let out = &camera.ports[0];
    assert_eq!(out.dir, Direction::Out);
    assert_eq!(out.rate, 1);
    assert_eq!(out.rate_span.map(|s| &VALID[s.range()]), Some("1"));
    assert_eq!(out.sample_type.as_deref(), Some("image"));
    assert_eq!(out.size, Some(76800));
    assert_eq!((out.kind, out.inner_rate), (None, None));

    let detect = &g.tasks[1];
    assert_eq!(detect.trigger, Trigger::Data);
    assert_eq!(
        detect.subgraph.as_ref().map(|s| &VALID[s.span.range()]),
        Some("detect.taskgraph.xml")
    );
    assert_eq!(detect.port("out").unwrap().rate, 2);
    assert_eq!(detect.port("img").unwrap().rate_span, None);
    let shared = &detect.library_ports[0];
    assert!(shared.master);
    assert_eq!(shared.library.name, "ColorList");
    let calls: Vec<&str> = shared.calls.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(calls, ["updateColor", "allFound", "reset"]);
    for c in &shared.calls {
        assert_eq!(&VALID[c.span.range()], c.name);
    }
    let warn = &detect.multicast_ports[0];
    assert_eq!(
        (warn.dir, warn.group.name.as_str()),
        (Direction::Out, "obstacle_alert")
    );

    let lib_task = &g.tasks[2];
    assert_eq!(lib_task.kind, TaskKind::Library);
    assert_eq!(lib_task.trigger, Trigger::Control);
    assert!(!lib_task.library_ports[0].master);

    let lib = &g.libraries[0];
    assert_eq!(lib.name.name, "ColorList");
    assert_eq!(lib.functions.len(), 3);
    assert_eq!(lib.functions[0].returns.as_deref(), Some("void"));
    assert_eq!(
        lib.functions[0].params,
        [("color".to_string(), "int".to_string())]
    );
    assert_eq!(lib.functions[2].returns, None);

    let train = &g.tasks[3];
    assert_eq!(train.kind, TaskKind::Loop);
    let l = train.loop_node.as_ref().unwrap();
    assert_eq!((l.loop_type, l.loop_count), (LoopType::C, 100));
    assert_eq!(
        l.exit_task.as_ref().map(|e| &VALID[e.span.range()]),
        Some("check_err")
    );
    assert_eq!(l.body.name, "train_body");
    let images = train.port("images").unwrap();
    assert_eq!(
        (images.rate, images.inner_rate, images.kind),
        (2, Some(2), Some(PortKind::Broadcasting))
    );
    assert_eq!(images.rate_span.map(|s| &VALID[s.range()]), Some("2"));
    assert_eq!(train.port("model").unwrap().kind, None);
    assert_eq!(l.body.channels.len(), 2);

    assert_eq!(g.channels.len(), 4);
    let c = &g.channels[0];
    assert_eq!(
        (c.src.task.as_str(), c.src.port.as_str()),
        ("camera", "out")
    );
    assert_eq!(&VALID[c.src.span.range()], "camera.out");
    assert_eq!(&VALID[c.dst.span.range()], "detect.in");
    assert_eq!((c.initial_tokens, c.capacity), (0, Some(4)));
    assert!(VALID[c.span.range()].starts_with("<Channel"));
    assert!(VALID[c.span.range()].ends_with("/>"));
    assert_eq!(g.channels[1].initial_tokens, 3);
    assert_eq!(g.channels[1].capacity, None);
}

#[test]
fn data_loop_facts() {
    let (graph, diags) = load(DATA_LOOP);
    assert!(diags.is_empty());
    let g = graph.unwrap();
    assert_eq!(g.name, "data_loop");
    let a = &g.tasks[g.task_index("A").unwrap()];
    assert_eq!(a.trigger, Trigger::Time { period_ms: 1000.0 });
    assert_eq!(a.port("o").unwrap().rate, 10);
    let l = &g.tasks[g.task_index("L").unwrap()];
    assert_eq!(l.kind, TaskKind::Loop);
    assert_eq!(l.trigger, Trigger::Data);
    let node = l.loop_node.as_ref().unwrap();
    assert_eq!(node.loop_type, LoopType::D);
    assert_eq!(node.loop_count, 10);
    assert_eq!(node.exit_task, None);
    let body: Vec<&str> = node
        .body
        .tasks
        .iter()
        .map(|t| t.name.name.as_str())
        .collect();
    assert_eq!(body, ["B", "C"]);
    assert_eq!(node.body.name, "L_body");
    assert_eq!(node.body.channels.len(), 3);
    assert_eq!(node.body.channels[0].src.task, "L");
    let input = l.port("in").unwrap();
    assert_eq!(input.dir, Direction::In);
    assert_eq!(input.rate, 10);
    assert_eq!(input.inner_rate, Some(1));
    assert_eq!(input.kind, Some(PortKind::Distributing));
    assert_eq!(
        g.tasks[g.task_index("D").unwrap()].port("i").unwrap().rate,
        10
    );
    assert_eq!(g.channels.len(), 2);
}

#[test]
fn kmeans_nests_a_data_loop_in_a_convergent_loop() {
    let (graph, _) = load(KMEANS);
    let g = graph.unwrap();
    let converge = g.tasks[g.task_index("Converge").unwrap()]
        .loop_node
        .as_ref()
        .unwrap();
    assert_eq!(
        (converge.loop_type, converge.loop_count),
        (LoopType::C, 500)
    );
    assert_eq!(converge.exit_task.as_ref().unwrap().name, "ReplaceCenter");
    let body = &converge.body;
    let assign = body.tasks[body.task_index("Assign").unwrap()]
        .loop_node
        .as_ref()
        .unwrap();
    assert_eq!((assign.loop_type, assign.loop_count), (LoopType::D, 16));
    assert_eq!(assign.body.tasks[0].name.name, "Nearest");
    assert_eq!(body.channels.len(), 6);
}

#[test]
fn shared_info_has_control_library_and_multicast() {
    let (graph, _) = load(SHARED_INFO);
    let g = graph.unwrap();
    let control = &g.tasks[g.task_index("ControlTask").unwrap()];
    assert_eq!(control.kind, TaskKind::Control);
    assert_eq!(control.library_ports.len(), 1);
    assert!(control.library_ports[0].calls.is_empty());
    assert_eq!(control.multicast_ports.len(), 2);
    assert_eq!(control.multicast_ports[1].dir, Direction::In);
    assert_eq!(g.libraries[0].functions.len(), 2);
    assert_eq!(
        g.tasks[g.task_index("ultrasonic").unwrap()].trigger,
        Trigger::Time { period_ms: 50.0 }
    );
}

#[test]
fn modem_facts() {
    let (graph, diags) = load(MODEM);
    assert!(diags.is_empty());
    let g = graph.unwrap();
    assert_eq!(g.name, "modem");
    assert!(MODEM[g.span.range()].starts_with("<sdf name=\"modem\""));
    assert_eq!(g.tasks.len(), 16);
    assert_eq!(g.channels.len(), 35);
    assert!(g.libraries.is_empty());
    assert!(g.tasks.iter().all(|t| t.kind == TaskKind::Computational
        && t.trigger == Trigger::Data
        && t.wcet == Some(1)));
    let hil = &g.tasks[g.task_index("hil").unwrap()];
    assert_eq!(hil.port("p_in").unwrap().rate, 8);
    assert_eq!(hil.port("p_in").unwrap().dir, Direction::In);
    assert_eq!(hil.port("p_out").unwrap().rate, 2);
    let eq = &g.tasks[g.task_index("eq").unwrap()];
    assert_eq!(eq.port("p_in1").unwrap().rate, 4);
    assert_eq!(eq.ports.len(), 5);
    let k = &g.channels[10];
    assert_eq!(
        (k.src.task.as_str(), k.src.port.as_str()),
        ("mul2", "p_out")
    );
    assert_eq!((k.dst.task.as_str(), k.dst.port.as_str()), ("eq", "p_in2"));
    assert_eq!(k.initial_tokens, 2);
    assert_eq!(g.channels[0].initial_tokens, 0);
    assert_eq!(
        g.channels.iter().filter(|c| c.initial_tokens > 0).count(),
        18
    );
}

#[test]
fn h263_takes_the_first_default_processor() {
    let (graph, diags) = load(H263);
    // Each with W086 on its second processor marked default.
    let warned: Vec<&str> = diags.iter().map(|d| &H263[d.span.range()]).collect();
    assert_eq!(warned, ["true", "true"], "{}", listing(&diags));
    assert!(
        diags[0].message.contains("actor `vld`"),
        "{}",
        listing(&diags)
    );
    let g = graph.unwrap();
    assert_eq!(g.name, "h263decoder");
    let wcet = |name: &str| g.tasks[g.task_index(name).unwrap()].wcet;
    // Two processors marked default: the first wins.
    assert_eq!(wcet("vld"), Some(26018));
    assert_eq!(wcet("iq"), Some(559));
    assert_eq!(wcet("idct"), Some(486));
    assert_eq!(wcet("mc"), Some(10958));
    assert_eq!(
        g.tasks[g.task_index("vld").unwrap()]
            .port("p0")
            .unwrap()
            .rate,
        594
    );
    assert_eq!(g.channels[3].initial_tokens, 1);
}

#[test]
fn sdf3_default_processor_or_first() {
    let text = r#"<sdf3 type="sdf"><applicationGraph name="app"><sdf name="g">
  <actor name="a"><port name="o" type="out" rate="2"/></actor>
  <actor name="b"><port name="i" type="in" rate="3"/></actor>
  <channel name="c" srcActor="a" srcPort="o" dstActor="b" dstPort="i" initialTokens="4"/>
  <unknownThing/>
</sdf>
<sdfProperties>
  <actorProperties actor="a">
    <processor type="x"><executionTime time="5"/></processor>
    <processor type="y" default="true"><executionTime time="7"/></processor>
  </actorProperties>
  <actorProperties actor="b">
    <processor type="x"><executionTime time="9"/></processor>
    <processor type="y"><executionTime time="11"/></processor>
  </actorProperties>
  <actorProperties actor="nobody"><processor type="x"><executionTime time="1"/></processor></actorProperties>
  <graphProperties><timeConstraints><throughput>0.5</throughput></timeConstraints></graphProperties>
</sdfProperties></applicationGraph></sdf3>"#;
    let (graph, diags) = load(text);
    assert!(diags.is_empty(), "{}", listing(&diags));
    let g = graph.unwrap();
    assert_eq!(g.tasks[0].wcet, Some(7));
    assert_eq!(g.tasks[1].wcet, Some(9));
    assert_eq!(g.channels[0].initial_tokens, 4);
    let src = &g.channels[0].src;
    assert_eq!(&text[src.span.range()], r#"a" srcPort="o"#);
}

// --- malformed XML (E060) -----------------------------------------------------

#[test]
fn unclosed_element_keeps_what_was_read() {
    let text = wrap(
        r#"<Task name="A"><Port name="o" dir="out"/></Task>
<Task name="B"><Port name="i" dir="in"/>"#,
    )
    .replace("</TaskGraph>\n", "");
    let (graph, diags) = load(&text);
    assert_eq!(diags.len(), 1, "{}", listing(&diags));
    assert_eq!(diags[0].code, Code::GraphXml);
    // The innermost element left open.
    assert_eq!(&text[diags[0].span.range()], r#"<Task name="B">"#);
    assert!(diags[0].message.contains("never closed"));
    let g = graph.unwrap();
    assert_eq!(g.tasks.len(), 2);
    assert_eq!(g.tasks[1].ports.len(), 1);
}

#[test]
fn mismatched_end_tag_points_at_both() {
    let text = wrap(r#"<Task name="A"><Port name="o" dir="out"/></Tsak>"#);
    let (graph, diags) = load(&text);
    assert_eq!(diags.len(), 1, "{}", listing(&diags));
    let d = &diags[0];
    assert_eq!(d.code, Code::GraphXml);
    assert_eq!(&text[d.span.range()], "</Tsak>");
    assert_eq!(&text[d.related[0].span.range()], r#"<Task name="A">"#);
    // What was read is kept: task A with its port, not yet closed.
    let g = graph.unwrap();
    assert_eq!(g.tasks[0].ports.len(), 1);
}

#[test]
fn syntax_error_stops_reading() {
    let text = wrap(
        r#"<Task name="A"><Port name="o" dir="out"/></Task>
<Task name="B" <Port/>
<Task name="C"/>"#,
    );
    let (graph, diags) = load(&text);
    assert_eq!(codes(&text), ["E060"], "{}", listing(&diags));
    let g = graph.unwrap();
    assert_eq!(g.tasks.len(), 1);
    // Channel ends are not checked in a graph that was cut short.
    let text = wrap(r#"<Channel src="A.o" dst="B.i"/><Task name="A" x="<"/>"#);
    assert_eq!(codes(&text), ["E060"]);
}

#[test]
fn bad_attribute_syntax_and_entities() {
    let (d, at) = only(&wrap(r#"<Task name=A/>"#));
    assert_eq!(d.code, Code::GraphXml);
    assert!(at.starts_with('A'), "{at}");
    let (d, _) = only(&wrap(r#"<Task name="A" name="B"/>"#));
    assert_eq!(d.code, Code::GraphXml);
    let (d, at) = only(&wrap("<Task name=\"A\"/>&nope;"));
    assert_eq!(d.code, Code::GraphXml);
    assert_eq!(at, "&nope;");
    // Known entities in values are fine.
    let (g, diags) = load(&wrap(r#"<Task name="A" source="a&amp;b.c"/>"#));
    assert!(diags.is_empty());
    assert_eq!(g.unwrap().tasks[0].source.as_deref(), Some("a&b.c"));
}

#[test]
fn empty_and_stray_text() {
    let (g, diags) = load("");
    assert!(g.is_none());
    assert_eq!(diags[0].code, Code::GraphXml);
    let (g, diags) = load("<?xml version=\"1.0\"?>\n<!-- only a comment -->\n");
    assert!(g.is_none());
    assert_eq!(diags.len(), 1);
    let (d, at) = only("hello <TaskGraph name=\"g\"/>");
    assert_eq!((d.code, at.as_str()), (Code::GraphXml, "hello"));
    let (d, at) = only("<TaskGraph name=\"g\"/>\n<TaskGraph name=\"h\"/>");
    assert_eq!((d.code, at.as_str()), (Code::GraphXml, "TaskGraph"));
    assert_eq!(d.span.start, 23);
    // A byte-order mark is not text.
    let (_, diags) = load("\u{feff}<TaskGraph name=\"g\"/>");
    assert!(diags.is_empty(), "{}", listing(&diags));
}

// --- unknown elements (E061) ------------------------------------------------

#[test]
fn unknown_element_points_at_its_name() {
    let text = wrap(r#"<Task name="A"><Prot name="o" dir="out"/></Task>"#);
    let (d, at) = only(&text);
    assert_eq!((d.code, at.as_str()), (Code::GraphUnknownElement, "Prot"));
    assert_eq!(d.suggestion.as_deref(), Some("Port"));
    // Its content is not looked at.
    let text = wrap(r#"<Stuff><Task/></Stuff>"#);
    assert_eq!(codes(&text), ["E061"]);
}

#[test]
fn misplaced_element_says_where_it_goes() {
    let (d, at) = only(&wrap(r#"<Port name="o" dir="out"/>"#));
    assert_eq!((d.code, at.as_str()), (Code::GraphUnknownElement, "Port"));
    assert!(
        d.message.contains("inside `<Task>` or `<Loop>`"),
        "{}",
        d.message
    );
    let (d, _) = only(&wrap(
        r#"<Task name="A"><LibrarySlavePort name="s" library="L"><Call function="f"/></LibrarySlavePort></Task>"#,
    ));
    assert_eq!(d.code, Code::GraphUnknownElement);
}

#[test]
fn unknown_root_and_text() {
    let (g, diags) = load("<Taskgraph name=\"g\"/>");
    assert!(g.is_none());
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].code, Code::GraphUnknownElement);
    assert_eq!(diags[0].suggestion.as_deref(), Some("TaskGraph"));
    let text = wrap(r#"<Task name="A">some words</Task>"#);
    let (d, at) = only(&text);
    assert_eq!(
        (d.code, at.as_str()),
        (Code::GraphUnknownElement, "some words")
    );
}

#[test]
fn loop_with_two_bodies() {
    let text = wrap(
        r#"<Loop name="L" type="D" loopCount="2"><TaskGraph name="a"/><TaskGraph name="b"/></Loop>"#,
    );
    let (d, at) = only(&text);
    assert_eq!(
        (d.code, at.as_str()),
        (Code::GraphUnknownElement, "TaskGraph")
    );
    assert!(d.span.start > text.find("name=\"a\"").unwrap());
}

// --- missing attributes (E062) ------------------------------------------------

#[test]
fn missing_attribute_points_at_the_start_tag() {
    let text = wrap(r#"<Task><Port name="o" dir="out"/></Task>"#);
    let (d, at) = only(&text);
    assert_eq!(
        (d.code, at.as_str()),
        (Code::GraphMissingAttribute, "<Task>")
    );
    assert!(d.message.contains("`name`"));

    let text = wrap(
        r#"<Task name="A"><Port name="o"/></Task><Task name="B"><Port name="i" dir="in"/></Task><Channel src="A.o" dst="B.i"/>"#,
    );
    // The broken port is left out, and the channel to it is not reported again.
    let (g, diags) = load(&text);
    assert_eq!(codes(&text), ["E062"], "{}", listing(&diags));
    assert!(g.unwrap().tasks[0].ports.is_empty());

    let (d, at) = only(&wrap(r#"<Channel src="A.o"/>"#));
    assert_eq!(
        (d.code, at.as_str()),
        (Code::GraphMissingAttribute, r#"<Channel src="A.o"/>"#)
    );
}

#[test]
fn time_trigger_needs_a_period_and_loop_needs_a_body() {
    let (d, at) = only(&wrap(r#"<Task name="A" trigger="time"/>"#));
    assert_eq!(
        (d.code, at.as_str()),
        (
            Code::GraphMissingAttribute,
            r#"<Task name="A" trigger="time"/>"#
        )
    );
    let (d, at) = only(&wrap(r#"<Loop name="L" type="D" loopCount="3"></Loop>"#));
    assert_eq!(
        (d.code, at.as_str()),
        (
            Code::GraphMissingAttribute,
            r#"<Loop name="L" type="D" loopCount="3">"#
        )
    );
    let (g, _) = load(&wrap(r#"<Loop name="L" type="D" loopCount="3"/>"#));
    let g = g.unwrap();
    assert!(g.tasks[0].loop_node.as_ref().unwrap().body.tasks.is_empty());
}

// --- duplicates (E063) --------------------------------------------------------

#[test]
fn duplicate_task_relates_the_first() {
    let text = wrap(r#"<Task name="A"/><Loop name="A" type="D" loopCount="1"><TaskGraph/></Loop>"#);
    let (g, diags) = load(&text);
    assert_eq!(diags.len(), 1, "{}", listing(&diags));
    let d = &diags[0];
    assert_eq!(d.code, Code::GraphDuplicateName);
    assert_eq!(&text[d.span.range()], "A");
    assert!(d.span.start > text.find("Loop").unwrap());
    assert_eq!(
        d.related[0].span,
        Span::new(text.find('A').unwrap(), text.find('A').unwrap() + 1)
    );
    assert_eq!(d.related[0].message, "first defined here");
    assert_eq!(g.unwrap().tasks.len(), 1);
}

#[test]
fn duplicate_ports_libraries_functions() {
    let text = wrap(
        r#"<Task name="A"><Port name="p" dir="out"/><MulticastPort name="p" dir="in" group="g"/></Task>"#,
    );
    let (d, at) = only(&text);
    assert_eq!((d.code, at.as_str()), (Code::GraphDuplicateName, "p"));
    assert!(d.span.start > text.find("Multicast").unwrap());

    let text = wrap(r#"<Library name="L"/><Library name="L"/>"#);
    assert_eq!(codes(&text), ["E063"]);
    let text = wrap(
        r#"<Library name="L"><Function name="f"/><Function name="f"><Param name="x" type="int"/><Param name="x" type="int"/></Function></Library>"#,
    );
    assert_eq!(codes(&text), ["E063", "E063"]);
    // A library and a task may share a name.
    assert!(codes(&wrap(r#"<Library name="L"/><Task name="L"/>"#)).is_empty());
}

#[test]
fn body_task_named_like_the_enclosing_loop() {
    let text = wrap(
        r#"<Loop name="L" type="D" loopCount="1"><TaskGraph name="b"><Task name="L"/></TaskGraph></Loop>"#,
    );
    let (d, at) = only(&text);
    assert_eq!((d.code, at.as_str()), (Code::GraphDuplicateName, "L"));
    assert!(d.message.contains("enclosing loop"));
}

// --- channel ends (E064, E066) ------------------------------------------------

const TWO: &str = r#"<Task name="camera"><Port name="out" dir="out"/><LibraryMasterPort name="lib" library="X"/></Task>
<Task name="detect"><Port name="in" dir="in"/><Port name="res" dir="out"/></Task>"#;

#[test]
fn unknown_task_and_port_with_did_you_mean() {
    let text = wrap(&format!(
        r#"{TWO}<Channel src="camra.out" dst="detect.in"/>"#
    ));
    let (d, at) = only(&text);
    assert_eq!((d.code, at.as_str()), (Code::GraphUnknownEndpoint, "camra"));
    assert_eq!(d.suggestion.as_deref(), Some("camera"));
    assert!(d.message.contains("did you mean `camera`?"));

    let text = wrap(&format!(
        r#"{TWO}<Channel src="camera.out" dst="detect.inn"/>"#
    ));
    let (d, at) = only(&text);
    assert_eq!((d.code, at.as_str()), (Code::GraphUnknownEndpoint, "inn"));
    assert_eq!(d.suggestion.as_deref(), Some("in"));

    let text = wrap(&format!(
        r#"{TWO}<Channel src="camera.lib" dst="detect.in"/>"#
    ));
    let (d, at) = only(&text);
    assert_eq!((d.code, at.as_str()), (Code::GraphUnknownEndpoint, "lib"));
    assert!(d.message.contains("library port"));
    // The channel is kept: analyses resolve ends themselves.
    let (g, _) = load(&text);
    assert_eq!(g.unwrap().channels.len(), 1);
}

#[test]
fn direction_mismatch() {
    let text = wrap(&format!(
        r#"{TWO}<Channel src="detect.in" dst="camera.out"/>"#
    ));
    let (g, diags) = load(&text);
    assert_eq!(codes(&text), ["E066", "E066"], "{}", listing(&diags));
    assert_eq!(&text[diags[0].span.range()], "detect.in");
    assert_eq!(&text[diags[1].span.range()], "camera.out");
    assert!(diags[0].message.contains("input port"));
    assert_eq!(&text[diags[0].related[0].span.range()], "in");
    assert_eq!(g.unwrap().channels.len(), 1);
}

#[test]
fn enclosing_loop_ports_inside_the_body() {
    let body = |channels: &str| {
        wrap(&format!(
            r#"<Loop name="L" type="D" loopCount="2">
  <Port name="in" dir="in" kind="distributing" outerRate="2"/>
  <Port name="out" dir="out" outerRate="2"/>
  <TaskGraph name="b"><Task name="B"><Port name="i" dir="in"/><Port name="o" dir="out"/></Task>{channels}</TaskGraph>
</Loop>"#
        ))
    };
    assert!(
        codes(&body(
            r#"<Channel src="L.in" dst="B.i"/><Channel src="B.o" dst="L.out"/>"#
        ))
        .is_empty()
    );
    let text = body(r#"<Channel src="L.out" dst="B.i"/><Channel src="B.o" dst="L.in"/>"#);
    let (_, diags) = load(&text);
    assert_eq!(codes(&text), ["E066", "E066"]);
    assert_eq!(&text[diags[0].span.range()], "L.out");
    assert!(diags[0].message.contains("enclosing loop"));
    let text = body(r#"<Channel src="L.inn" dst="B.i"/><Channel src="B.o" dst="M.out"/>"#);
    let (_, diags) = load(&text);
    assert_eq!(codes(&text), ["E064", "E064"], "{}", listing(&diags));
    assert_eq!(diags[0].suggestion.as_deref(), Some("in"));
    assert!(diags[0].message.contains("enclosing loop"));
    // Outside its body, a loop node's ports keep their own direction.
    let text = wrap(
        r#"<Task name="A"><Port name="o" dir="out"/></Task>
<Loop name="L" type="C" loopCount="2"><Port name="in" dir="in"/><TaskGraph/></Loop>
<Channel src="A.o" dst="L.in"/><Channel src="L.in" dst="A.o"/>"#,
    );
    assert_eq!(codes(&text), ["E066", "E066"]);
}

#[test]
fn a_port_on_two_channels_is_refused_at_the_second() {
    // Our format: the second channel's end, related to the first's.
    let text = wrap(
        r#"<Task name="A"><Port name="o" dir="out"/></Task>
<Task name="B"><Port name="i" dir="in"/></Task>
<Task name="C"><Port name="i" dir="in"/></Task>
<Channel src="A.o" dst="B.i"/>
<Channel src="A.o" dst="C.i"/>"#,
    );
    let (g, diags) = load(&text);
    assert_eq!(codes(&text), ["E098"], "{}", listing(&diags));
    let second = text.rfind("A.o").unwrap();
    assert_eq!(diags[0].span.range(), second..second + 3);
    assert_eq!(
        diags[0].related[0].span.range().start,
        text.find("A.o\"").unwrap()
    );
    assert!(diags[0].message.contains("`A.o`"), "{}", listing(&diags));
    // Both channels stay in the graph; the analyses do not run on it.
    assert_eq!(g.unwrap().channels.len(), 2);
    // A loop's port joined once outside and once inside its body is two
    // channels at two levels: allowed.
    let text = wrap(
        r#"<Task name="A"><Port name="o" dir="out"/></Task>
<Loop name="L" type="D" loopCount="1"><Port name="in" dir="in"/>
<TaskGraph name="b"><Task name="B"><Port name="i" dir="in"/></Task><Channel src="L.in" dst="B.i"/></TaskGraph></Loop>
<Channel src="A.o" dst="L.in"/>"#,
    );
    assert!(codes(&text).is_empty(), "{:?}", codes(&text));
    // SDF3: the same, and the clean reader leaves it to the full one.
    let text = r#"<sdf3 type="sdf"><applicationGraph><sdf name="g">
  <actor name="a"><port name="o" type="out" rate="1"/></actor>
  <actor name="b"><port name="i" type="in" rate="1"/></actor>
  <channel name="c1" srcActor="a" srcPort="o" dstActor="b" dstPort="i"/>
  <channel name="c2" srcActor="a" srcPort="o" dstActor="b" dstPort="i"/>
</sdf></applicationGraph></sdf3>"#;
    assert_eq!(codes(text), ["E098", "E098"]);
    assert_clean_reader_agrees(text, ExecutionTimes::FileDefault);
    assert!(sdf3_clean::read(FILE, text, ExecutionTimes::FileDefault).is_none());
}

#[test]
fn two_default_processors_are_a_warning_and_the_first_gives_the_time() {
    let text = r#"<sdf3 type="sdf"><applicationGraph><sdf name="g">
  <actor name="a"><port name="o" type="out" rate="1"/><port name="i" type="in" rate="1"/></actor>
  <channel name="l" srcActor="a" srcPort="o" dstActor="a" dstPort="i" initialTokens="1"/>
</sdf><sdfProperties><actorProperties actor="a">
  <processor type="arm" default="true"><executionTime time="20"/></processor>
  <processor type="dsp" default="true"><executionTime time="10"/></processor>
</actorProperties></sdfProperties></applicationGraph></sdf3>"#;
    for (times, wcet) in [
        (ExecutionTimes::FileDefault, 20),
        (ExecutionTimes::Sdf3Compat, 10),
    ] {
        let (g, diags) = load_fully(FILE, text, times);
        assert_eq!(diags.len(), 1, "{}", listing(&diags));
        assert_eq!(diags[0].code, Code::Sdf3TwoDefaultProcessors);
        let second = text.rfind("true").unwrap();
        assert_eq!(diags[0].span.range(), second..second + 4);
        assert_eq!(g.unwrap().tasks[0].wcet, Some(wcet));
        assert_clean_reader_agrees(text, times);
    }
    // One marked `true`, another `false`: no warning.
    let once = text.replacen(r#"dsp" default="true"#, r#"dsp" default="false"#, 1);
    assert!(codes(&once).is_empty());
}

#[test]
fn sdf3_channel_checks() {
    let text = r#"<sdf3 type="sdf"><applicationGraph><sdf name="g">
  <actor name="alpha"><port name="o" type="out" rate="1"/></actor>
  <actor name="beta"><port name="i" type="in" rate="1"/></actor>
  <channel name="c1" srcActor="alpah" srcPort="o" dstActor="beta" dstPort="i"/>
  <channel name="c2" srcActor="alpha" srcPort="x" dstActor="beta" dstPort="i"/>
  <channel name="c3" srcActor="beta" srcPort="i" dstActor="alpha" dstPort="o"/>
  <channel name="c4" srcActor="alpha" srcPort="o" dstActor="beta"/>
</sdf></applicationGraph></sdf3>"#;
    let (g, diags) = load(text);
    let got: Vec<(&str, &str)> = diags
        .iter()
        .map(|d| (d.code.as_str(), &text[d.span.range()]))
        .collect();
    assert_eq!(
        got,
        [
            ("E064", "alpah"),
            ("E064", "x"),
            // c2 ends at `beta.i` too, which c1 joins already.
            ("E098", r#"beta" dstPort="i"#),
            ("E066", r#"beta" srcPort="i"#),
            ("E066", r#"alpha" dstPort="o"#),
            (
                "E062",
                r#"<channel name="c4" srcActor="alpha" srcPort="o" dstActor="beta"/>"#
            ),
        ],
        "{}",
        listing(&diags)
    );
    assert!(diags[0].message.contains("actor"));
    assert_eq!(diags[0].suggestion.as_deref(), Some("alpha"));
    assert_eq!(g.unwrap().channels.len(), 3);
}

#[test]
fn sdf3_other_graph_types_and_missing_graph() {
    let (g, diags) =
        load(r#"<sdf3 type="csdf"><applicationGraph><csdf/></applicationGraph></sdf3>"#);
    assert!(g.is_none());
    assert_eq!(diags.len(), 1);
    assert_eq!(diags[0].code, Code::GraphBadAttribute);
    let (g, diags) = load(r#"<sdf3 type="sdf"/>"#);
    assert!(g.is_none());
    assert_eq!(diags[0].code, Code::GraphMissingAttribute);
    let text = r#"<sdf3><applicationGraph><sdf name="g"><actor name="a"><port name="o" type="inout" rate="0"/></actor><actor name="a"/></sdf></applicationGraph></sdf3>"#;
    assert_eq!(codes(text), ["E062", "E065", "E065", "E063"]);
}

// --- bad values (E065) --------------------------------------------------------

#[test]
fn bad_values_point_at_the_value() {
    let cases: &[(&str, &str)] = &[
        (
            r#"<Task name="A"><Port name="o" dir="out" rate="0"/></Task>"#,
            "0",
        ),
        (
            r#"<Task name="A"><Port name="o" dir="out" rate="two"/></Task>"#,
            "two",
        ),
        (
            r#"<Task name="A"><Port name="o" dir="out" rate="-1"/></Task>"#,
            "-1",
        ),
        (
            r#"<Task name="A"><Port name="o" dir="out" rate="99999999999999999999999"/></Task>"#,
            "99999999999999999999999",
        ),
        (
            r#"<Task name="A"><Port name="o" dir="outt"/></Task>"#,
            "outt",
        ),
        (
            r#"<Task name="A"><Port name="o" dir="out" size="big"/></Task>"#,
            "big",
        ),
        (r#"<Task name="A" kind="computer"/>"#, "computer"),
        (r#"<Task name="A" kind="loop"/>"#, "loop"),
        (
            r#"<Task name="A" trigger="timer" period="1 SEC"/>"#,
            "timer",
        ),
        (
            r#"<Task name="A" trigger="time" period="33MSEC"/>"#,
            "33MSEC",
        ),
        (
            r#"<Task name="A" trigger="time" period="33 FORTNIGHTS"/>"#,
            "33 FORTNIGHTS",
        ),
        (r#"<Task name="A" trigger="time" period="0 SEC"/>"#, "0 SEC"),
        (r#"<Task name="A" trigger="data" period="1 SEC"/>"#, "1 SEC"),
        (r#"<Task name="A" wcet="1.5"/>"#, "1.5"),
        (r#"<Task name="2A"/>"#, "2A"),
        (r#"<Task name=" "/>"#, " "),
        (
            r#"<Loop name="L" type="X" loopCount="2"><TaskGraph/></Loop>"#,
            "X",
        ),
        (
            r#"<Loop name="L" type="D" loopCount="0"><TaskGraph/></Loop>"#,
            "0",
        ),
        (
            r#"<Loop name="L" type="C" loopCount="2"><Port name="o" dir="out" kind="broadcasting"/><TaskGraph/></Loop>"#,
            "broadcasting",
        ),
        (
            r#"<Loop name="L" type="C" loopCount="2"><Port name="i" dir="in" kind="sharing"/><TaskGraph/></Loop>"#,
            "sharing",
        ),
        (
            r#"<Loop name="L" type="C" loopCount="2"><Port name="i" dir="in" innerRate="0"/><TaskGraph/></Loop>"#,
            "0",
        ),
        (r#"<Channel src="A" dst="B.i"/>"#, "A"),
        (r#"<Channel src="A.o.x" dst="B.i"/>"#, "A.o.x"),
        (r#"<Channel src=".o" dst="B.i"/>"#, ".o"),
    ];
    for (body, value) in cases {
        let text = wrap(body);
        let (d, at) = only(&text);
        assert_eq!(
            (d.code, at.as_str()),
            (Code::GraphBadAttribute, *value),
            "{body}"
        );
    }
    let text = wrap(&format!(
        r#"{TWO}<Channel src="camera.out" dst="detect.in" initialTokens="x" capacity="0"/>"#
    ));
    let (g, diags) = load(&text);
    let got: Vec<&str> = diags.iter().map(|d| &text[d.span.range()]).collect();
    assert_eq!(got, ["x", "0"]);
    // A channel with bad initial tokens is left out.
    assert!(g.unwrap().channels.is_empty());
}

#[test]
fn bad_value_suggestions() {
    let (d, _) = only(&wrap(r#"<Task name="A" kind="contrl"/>"#));
    assert_eq!(d.suggestion.as_deref(), Some("control"));
    let (d, _) = only(&wrap(r#"<Task name="A"><Port name="o" dir="Out"/></Task>"#));
    assert_eq!(d.suggestion.as_deref(), Some("out"));
}

#[test]
fn periods() {
    let period = |p: &str| {
        let (g, diags) = load(&wrap(&format!(
            r#"<Task name="A" trigger="time" period="{p}"/>"#
        )));
        assert!(diags.is_empty(), "{p}: {}", listing(&diags));
        match g.unwrap().tasks[0].trigger {
            Trigger::Time { period_ms } => period_ms,
            ref t => panic!("{t:?}"),
        }
    };
    assert_eq!(period("33 MSEC"), 33.0);
    assert_eq!(period("1 SEC"), 1000.0);
    assert_eq!(period(" 2.5  sec "), 2500.0);
    assert_eq!(period("1 MIN"), 60_000.0);
    assert_eq!(period("1 HOUR"), 3_600_000.0);
}

// --- unknown attributes (W060) ------------------------------------------------

#[test]
fn unknown_attribute_points_at_its_name() {
    let text = wrap(r#"<Task name="A" wect="3"/>"#);
    let (d, at) = only(&text);
    assert_eq!((d.code, at.as_str()), (Code::GraphUnknownAttribute, "wect"));
    assert_eq!(d.severity, crate::diag::Severity::Warning);
    assert_eq!(d.suggestion.as_deref(), Some("wcet"));
    // Namespaces are fine everywhere.
    assert!(codes(&wrap(r#"<Task name="A" xmlns:x="u" x:note="n"/>"#)).is_empty());
    // `rate` is not an attribute of a loop node's port, nor `calls` of a slave port.
    let text = wrap(
        r#"<Loop name="L" type="D" loopCount="1"><Port name="i" dir="in" rate="1"/><TaskGraph/></Loop>
<Task name="T"><LibrarySlavePort name="s" library="X" calls="f"/></Task>"#,
    );
    let (_, diags) = load(&text);
    assert_eq!(codes(&text), ["W060", "W060"]);
    assert_eq!(diags[0].suggestion.as_deref(), Some("outerRate"));
}

#[test]
fn broken_ports_are_not_reported_again() {
    // The loop's port `in` is left out (bad rate); the body's channel from it
    // and the outer channel to it are not reported a second time.
    let text = wrap(
        r#"<Task name="A"><Port name="o" dir="out"/></Task>
<Loop name="L" type="D" loopCount="2">
  <Port name="in" dir="in" outerRate="x"/>
  <TaskGraph><Task name="B"><Port name="i" dir="in"/></Task><Channel src="L.in" dst="B.i"/></TaskGraph>
</Loop>
<Channel src="A.o" dst="L.in"/>"#,
    );
    assert_eq!(codes(&text), ["E065"]);
    // Same for a loop left out (bad loopCount).
    let text = wrap(
        r#"<Task name="A"><Port name="o" dir="out"/></Task>
<Loop name="L" type="D" loopCount="many"><Port name="in" dir="in"/><TaskGraph/></Loop>
<Channel src="A.o" dst="L.in"/>"#,
    );
    let (g, _) = load(&text);
    assert_eq!(codes(&text), ["E065"]);
    assert_eq!(g.unwrap().tasks.len(), 1);
}

// --- robustness -----------------------------------------------------------------

#[test]
fn every_prefix_of_an_example_loads() {
    for end in 0..=KMEANS.len() {
        if KMEANS.is_char_boundary(end) {
            let text = &KMEANS[..end];
            let (_, diags) = load(text);
            if end < KMEANS.trim_end().len() {
                assert!(
                    diags.iter().any(|d| d.code == Code::GraphXml),
                    "prefix {end}: {}",
                    listing(&diags)
                );
            }
        }
    }
}

#[test]
fn detect_format_from_the_root() {
    assert_eq!(detect_format(VALID), Some(GraphFormat::SemoXml));
    assert_eq!(detect_format(MODEM), Some(GraphFormat::Sdf3));
    assert_eq!(detect_format("<Catalog/>"), None);
    assert_eq!(detect_format(""), None);
}

fn mutate(base: &str, edits: Vec<(prop::sample::Index, u8, u8)>) -> String {
    let mut bytes = base.as_bytes().to_vec();
    for (index, byte, op) in edits {
        if bytes.is_empty() {
            bytes.push(byte);
            continue;
        }
        let i = index.index(bytes.len());
        let byte = match byte % 10 {
            0 => b'<',
            1 => b'>',
            2 => b'"',
            3 => b'/',
            4 => b'&',
            5 => b'.',
            6 => b'0',
            _ => byte,
        };
        match op {
            0 => bytes[i] = byte,
            1 => bytes.insert(i, byte),
            2 => {
                bytes.remove(i);
            }
            _ => {
                let end = (i + 1 + byte as usize % 40).min(bytes.len());
                bytes.drain(i..end);
            }
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// The clean SDF3 reader on `text`, against the full reader: it declines
/// exactly the files the full reader reports something in (or that hold an
/// entity, which it leaves to the full reader), and gives the full reader's
/// graph on every other.
fn assert_clean_reader_agrees(text: &str, times: ExecutionTimes) {
    let clean = sdf3_clean::read(FILE, text, times);
    let (full, diags) = load_fully(FILE, text, times);
    let full_is_clean = diags.is_empty() && full.is_some();
    let is_sdf3 = detect_format(text) == Some(GraphFormat::Sdf3);
    match clean {
        Some(graph) => {
            assert!(
                full_is_clean,
                "accepted, but the full reader says:\n{}",
                listing(&diags)
            );
            assert_eq!(Some(graph), full);
        }
        None => assert!(
            !full_is_clean || !is_sdf3 || text.contains('&'),
            "declined a file the full reader reads silently"
        ),
    }
}

#[test]
fn the_clean_sdf3_reader_reads_every_sdf3_graph_as_the_full_reader_does() {
    let mut files = files_in(SDF3, ".xml");
    files.extend(files_in(&format!("{SDF3}/generated"), ".xml"));
    assert!(files.len() > 40, "{files:?}");
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        for times in [ExecutionTimes::FileDefault, ExecutionTimes::Sdf3Compat] {
            let clean = sdf3_clean::read(FILE, &text, times);
            let (full, diags) = load_fully(FILE, &text, times);
            assert_benchmark_diagnostics(&path, &diags);
            if diags.is_empty() {
                assert!(clean.is_some(), "{} was declined", path.display());
                assert_eq!(clean, full, "{}", path.display());
            } else {
                assert!(clean.is_none(), "{} has W086", path.display());
            }
        }
    }
}

#[test]
fn the_clean_sdf3_reader_declines_what_the_full_reader_reports() {
    let graph = |actors: &str, channels: &str, properties: &str| {
        format!(
            r#"<?xml version="1.0"?>
<sdf3 type="sdf" version="1.0"><applicationGraph name="app"><sdf name="g" type="G">
{actors}
{channels}
</sdf><sdfProperties>{properties}</sdfProperties></applicationGraph></sdf3>"#
        )
    };
    let actors = r#"<actor name="a" type="A"><port name="o" type="out" rate="2"/><port name="i" type="in" rate="1"/></actor>
<actor name="b" type="B"><port name="i" type="in" rate="1"/><port name="o" type="out"/></actor>"#;
    let channels = r#"<channel name="c0" srcActor="a" srcPort="o" dstActor="b" dstPort="i"/>
<channel name="c1" srcActor="b" srcPort="o" dstActor="a" dstPort="i" initialTokens="1"/>"#;
    let properties = r#"<actorProperties actor="a"><processor type="p1" default="true"><executionTime time="3"/></processor></actorProperties>
<actorProperties actor="b"><processor type="p1"><executionTime time="5"/></processor><processor type="p2" default="false"><executionTime time="7"/></processor></actorProperties>"#;
    let clean = graph(actors, channels, properties);
    for times in [ExecutionTimes::FileDefault, ExecutionTimes::Sdf3Compat] {
        assert_clean_reader_agrees(&clean, times);
        assert!(sdf3_clean::read(FILE, &clean, times).is_some());
    }
    let g = sdf3_clean::read(FILE, &clean, ExecutionTimes::Sdf3Compat).unwrap();
    assert_eq!(g.tasks[1].wcet, Some(7));
    // Elements SDF3's reading does not use are ignored silently by both.
    let other = clean.replace("<sdf name", "<other x=\"1\"><port/></other><sdf name");
    assert!(sdf3_clean::read(FILE, &other, ExecutionTimes::FileDefault).is_some());
    assert_clean_reader_agrees(&other, ExecutionTimes::FileDefault);
    // One change each, every one reported by the full reader (or an entity).
    let broken = [
        clean.replace("type=\"sdf\"", "type=\"csdf\""),
        clean.replace(" type=\"sdf\"", ""),
        clean.replace("name=\"b\" type", "name=\"a\" type"),
        clean.replace("name=\"b\" type", "type"),
        clean.replace("name=\"o\" type=\"out\"/>", "name=\"i\" type=\"out\"/>"),
        clean.replace(
            "type=\"in\" rate=\"1\"/></actor>\n",
            "type=\"inout\" rate=\"1\"/></actor>\n",
        ),
        clean.replace("rate=\"2\"", "rate=\"0\""),
        clean.replace("rate=\"2\"", "rate=\" 2x\""),
        clean.replace("rate=\"2\"", "rate=\"99999999999999999999999\""),
        clean.replace("dstPort=\"i\"/>", "dstPort=\"x\"/>"),
        clean.replace("dstActor=\"b\"", "dstActor=\"c\""),
        clean.replace(
            "srcPort=\"o\" dstActor=\"b\"",
            "srcPort=\"i\" dstActor=\"b\"",
        ),
        clean.replace("initialTokens=\"1\"", "initialTokens=\"-1\""),
        clean.replace("time=\"3\"", "time=\"\""),
        clean.replace("srcActor=\"a\"", "srcActor=\" \""),
        clean.replace("name=\"app\"", "name=\"a&amp;b\""),
        clean.replace("name=\"app\"", "name=\"a<b\""),
        clean.replace("name=\"app\"", "name=\"app\" name=\"x\""),
        clean.replace("</sdf>", ""),
        clean.replace("<?xml version=\"1.0\"?>", "text"),
        format!("{clean}<sdf3 type=\"sdf\"/>"),
        graph(actors, channels, properties)
            .replace("<sdf name=\"g\" type=\"G\">", "<sdfx>")
            .replace("</sdf>", "</sdfx>"),
    ];
    for (i, text) in broken.iter().enumerate() {
        for times in [ExecutionTimes::FileDefault, ExecutionTimes::Sdf3Compat] {
            assert!(
                sdf3_clean::read(FILE, text, times).is_none(),
                "case {i}:\n{text}"
            );
            assert_clean_reader_agrees(text, times);
        }
    }
    // After a byte-order mark, both give the same graph, every range three
    // bytes on.
    let marked = format!("\u{feff}{clean}");
    let g = sdf3_clean::read(FILE, &clean, ExecutionTimes::FileDefault).unwrap();
    let m = sdf3_clean::read(FILE, &marked, ExecutionTimes::FileDefault).unwrap();
    assert_clean_reader_agrees(&marked, ExecutionTimes::FileDefault);
    assert_eq!(m.span, Span::new(g.span.start + 3, g.span.end + 3));
    assert_eq!(m.channels[1].span.end, g.channels[1].span.end + 3);
    // Our format and other roots are never read by it.
    assert!(sdf3_clean::read(FILE, VALID, ExecutionTimes::FileDefault).is_none());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1500))]

    #[test]
    fn never_panics_on_mutations(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..4), 1..8)
    ) {
        let text = mutate(VALID, edits);
        load(&text);
    }

    #[test]
    fn never_panics_on_sdf3_mutations(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..4), 1..8)
    ) {
        let text = mutate(H263, edits);
        load(&text);
    }

    #[test]
    fn the_clean_sdf3_reader_agrees_with_the_full_reader_on_mutations(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>(), 0u8..4), 1..4),
        compat in any::<bool>(),
    ) {
        let times = if compat { ExecutionTimes::Sdf3Compat } else { ExecutionTimes::FileDefault };
        assert_clean_reader_agrees(&mutate(H263, edits.clone()), times);
        assert_clean_reader_agrees(&mutate(MODEM, edits), times);
    }

    #[test]
    fn never_panics_on_arbitrary_text(text in "[<>/=\"'&;.a-zA-Z0-9: \n!?\\-\\[\\]é]{0,200}") {
        load(&text);
    }
}

#[test]
fn diagnostic_fixtures_produce_only_their_code() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/fixtures/diagnostics");
    let mut seen = 0;
    for entry in std::fs::read_dir(root).unwrap() {
        let dir = entry.unwrap().path();
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let path = dir.join("graph.taskgraph.xml");
        // The loader's own codes; the analyses' fixtures are checked elsewhere.
        let loader_codes = [
            "E060", "E061", "E062", "E063", "E064", "E065", "E066", "W060",
        ];
        if !loader_codes.iter().any(|c| name.starts_with(c)) || !path.is_file() {
            continue;
        }
        let code = Code::from_code(&name[..4]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let (graph, diags) = load(&text);
        println!("{name}:\n{}", listing(&diags));
        assert!(!diags.is_empty(), "{name}");
        assert!(
            diags.iter().all(|d| d.code == code),
            "{name}: {}",
            listing(&diags)
        );
        assert!(graph.is_some(), "{name}");
        seen += 1;
    }
    assert_eq!(seen, 8);
}

/// The vocabulary tables list exactly the elements the readers read: every
/// element of our format (each once, a `<Port>` twice: a task's and a loop
/// node's), and for SDF3 every element with a role under some parent.
#[test]
fn vocabularies_are_the_readers_elements() {
    let mut listed: Vec<&str> = SEMO_VOCABULARY.iter().map(|(e, _)| *e).collect();
    listed.dedup();
    let mut known: Vec<&str> = SEMO_ELEMENTS.iter().map(|(e, _)| *e).collect();
    listed.sort_unstable();
    known.sort_unstable();
    assert_eq!(listed, known);
    use sdf3::Role;
    let parents = [
        Role::Root,
        Role::ApplicationGraph,
        Role::Sdf,
        Role::Actor,
        Role::Properties,
        Role::ActorProperties,
        Role::Processor,
    ];
    let (root, inner) = SDF3_VOCABULARY.split_first().unwrap();
    assert_eq!(root.0, "sdf3");
    for (element, _) in inner {
        assert!(
            parents
                .iter()
                .any(|p| p.child(element.as_bytes(), |_| true) != Role::Ignored),
            "{element} is read by no role"
        );
    }
    // The roles below the root: the parents but the root, then the leaves
    // `port`, `channel` and `executionTime`.
    assert_eq!(
        inner.len(),
        parents.len() - 1 + 3,
        "a role without an entry"
    );
}
