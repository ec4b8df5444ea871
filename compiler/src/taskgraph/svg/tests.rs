//! The pictures of every reference example and SDF3 benchmark, read back as
//! XML: well-formed, every task a labelled node, no overlapping boxes,
//! clusters around their contents, edges ending at their nodes.

use super::to_svg;
use crate::diag::FileId;
use crate::taskgraph::{TaskGraph, load_task_graph};
use proptest::prelude::*;
use quick_xml::Reader;
use quick_xml::events::Event;
use std::collections::HashMap;
use std::fmt::Write;

// --- A small DOM of the SVG ---------------------------------------------------

struct Elem {
    name: String,
    attrs: HashMap<String, String>,
    text: String,
    children: Vec<usize>,
}

impl Elem {
    fn attr(&self, key: &str) -> &str {
        self.attrs.get(key).map_or("", String::as_str)
    }

    fn num(&self, key: &str) -> f64 {
        self.attr(key)
            .parse()
            .unwrap_or_else(|_| panic!("<{}> {key}={:?}", self.name, self.attr(key)))
    }
}

/// The elements in document order (0 is the root); panics unless the text
/// is well-formed XML with one root element.
fn parse(svg: &str) -> Vec<Elem> {
    let mut reader = Reader::from_str(svg);
    reader.config_mut().check_end_names = true;
    let mut elems: Vec<Elem> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    let mut roots = 0;
    loop {
        let event = reader
            .read_event()
            .unwrap_or_else(|e| panic!("malformed SVG at {}: {e}", reader.error_position()));
        let mut open = |e: &quick_xml::events::BytesStart, elems: &mut Vec<Elem>| {
            let mut attrs = HashMap::new();
            for a in e.attributes() {
                let a = a.expect("well-formed attribute");
                let key = String::from_utf8(a.key.as_ref().to_vec()).unwrap();
                let value = a
                    .decode_and_unescape_value(reader.decoder())
                    .expect("attribute value unescapes")
                    .into_owned();
                assert!(attrs.insert(key, value).is_none(), "duplicate attribute");
            }
            let name = String::from_utf8(e.name().as_ref().to_vec()).unwrap();
            elems.push(Elem {
                name,
                attrs,
                text: String::new(),
                children: Vec::new(),
            });
            let index = elems.len() - 1;
            match stack.last() {
                Some(&parent) => elems[parent].children.push(index),
                None => roots += 1,
            }
            index
        };
        match event {
            Event::Start(e) => {
                let index = open(&e, &mut elems);
                stack.push(index);
            }
            Event::Empty(e) => {
                open(&e, &mut elems);
            }
            Event::End(_) => {
                stack.pop().expect("an end tag closes an element");
            }
            Event::Text(t) => {
                let text = t.decode().expect("UTF-8 text");
                if let Some(&top) = stack.last() {
                    elems[top].text.push_str(&text);
                } else {
                    assert!(text.trim().is_empty(), "text outside the root: {text:?}");
                }
            }
            Event::GeneralRef(r) => {
                let name = r.decode().expect("UTF-8 reference").into_owned();
                let c = match name.as_str() {
                    "amp" => '&',
                    "lt" => '<',
                    "gt" => '>',
                    "quot" => '"',
                    "apos" => '\'',
                    other => panic!("unexpected reference &{other};"),
                };
                let top = *stack.last().expect("a reference inside an element");
                elems[top].text.push(c);
            }
            Event::Eof => break,
            Event::CData(_) | Event::Comment(_) | Event::Decl(_) | Event::PI(_) => {}
            Event::DocType(_) => panic!("no DOCTYPE expected"),
        }
    }
    assert!(stack.is_empty(), "unclosed elements");
    assert_eq!(roots, 1, "one root element");
    elems
}

// --- What the picture shows ----------------------------------------------------

#[derive(Clone, Copy, Debug)]
struct Box2 {
    x: f64,
    y: f64,
    w: f64,
    h: f64,
}

impl Box2 {
    /// Distance from `(px, py)` to the rectangle (0 inside).
    fn distance(&self, px: f64, py: f64) -> f64 {
        let dx = (self.x - px).max(px - (self.x + self.w)).max(0.0);
        let dy = (self.y - py).max(py - (self.y + self.h)).max(0.0);
        dx.hypot(dy)
    }

    fn overlaps(&self, o: &Box2) -> bool {
        self.x < o.x + o.w && o.x < self.x + self.w && self.y < o.y + o.h && o.y < self.y + self.h
    }

    fn contains(&self, o: &Box2, slack: f64) -> bool {
        o.x >= self.x - slack
            && o.y >= self.y - slack
            && o.x + o.w <= self.x + self.w + slack
            && o.y + o.h <= self.y + self.h + slack
    }
}

struct Shape {
    class: String,
    bounds: Box2,
    texts: Vec<String>,
}

struct EdgeSeen {
    class: String,
    from: String,
    to: String,
    start: (f64, f64),
    end: (f64, f64),
    labels: Vec<String>,
}

struct Picture {
    /// By `data-path`: nodes, clusters, ports and relays.
    shapes: HashMap<String, Shape>,
    edges: Vec<EdgeSeen>,
    view: Box2,
}

fn first_child<'e>(elems: &'e [Elem], e: &Elem, name: &str) -> Option<&'e Elem> {
    e.children
        .iter()
        .map(|&c| &elems[c])
        .find(|c| c.name == name)
}

/// The first and last points of a path's `d` (M, L and C commands only).
fn path_ends(d: &str) -> ((f64, f64), (f64, f64)) {
    let numbers: Vec<f64> = d
        .split(['M', 'L', 'C', ',', ' '])
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap_or_else(|_| panic!("number in {d:?}")))
        .collect();
    assert!(numbers.len() >= 4 && numbers.len() % 2 == 0, "path {d:?}");
    let n = numbers.len();
    ((numbers[0], numbers[1]), (numbers[n - 2], numbers[n - 1]))
}

fn read_picture(svg: &str) -> Picture {
    let elems = parse(svg);
    let root = &elems[0];
    assert_eq!(root.name, "svg");
    assert_eq!(root.attr("xmlns"), "http://www.w3.org/2000/svg");
    let view: Vec<f64> = root
        .attr("viewBox")
        .split(' ')
        .map(|s| s.parse().expect("viewBox numbers"))
        .collect();
    assert_eq!(view.len(), 4);
    assert!(view[2] > 0.0 && view[3] > 0.0);
    let mut shapes = HashMap::new();
    let mut edges = Vec::new();
    for e in elems.iter().filter(|e| e.name == "g") {
        let class = e.attr("class").to_string();
        let texts: Vec<String> = e
            .children
            .iter()
            .map(|&c| &elems[c])
            .filter(|c| c.name == "text")
            .map(|c| c.text.clone())
            .collect();
        if class.starts_with("edge") {
            let path = first_child(&elems, e, "path").expect("an edge has a path");
            let (start, end) = path_ends(path.attr("d"));
            edges.push(EdgeSeen {
                class,
                from: e.attr("data-from").to_string(),
                to: e.attr("data-to").to_string(),
                start,
                end,
                labels: texts,
            });
            continue;
        }
        let bounds = if let Some(rect) = first_child(&elems, e, "rect") {
            Box2 {
                x: rect.num("x"),
                y: rect.num("y"),
                w: rect.num("width"),
                h: rect.num("height"),
            }
        } else if let Some(circle) = first_child(&elems, e, "circle") {
            Box2 {
                x: circle.num("cx"),
                y: circle.num("cy"),
                w: 0.0,
                h: 0.0,
            }
        } else {
            panic!("group {class} has no shape");
        };
        let path = e.attr("data-path").to_string();
        assert!(!path.is_empty(), "{class} without data-path");
        let shape = Shape {
            class,
            bounds,
            texts,
        };
        assert!(
            shapes.insert(path.clone(), shape).is_none(),
            "two shapes named {path}"
        );
    }
    Picture {
        shapes,
        edges,
        view: Box2 {
            x: view[0],
            y: view[1],
            w: view[2],
            h: view[3],
        },
    }
}

/// The cluster a shape is drawn in: `L/B` and `L.in` are in `L`.
fn parent(path: &str) -> Option<&str> {
    let slash = path.rfind('/');
    let after = slash.map_or(0, |s| s + 1);
    match path[after..].find('.') {
        // A port or relay of the cluster `path[..dot]`.
        Some(dot) if !path.starts_with("library ") && !path.starts_with("multicast ") => {
            Some(&path[..after + dot])
        }
        _ => slash.map(|s| &path[..s]),
    }
}

/// Every task of `graph` (loops included), with its path in the picture.
fn task_paths(graph: &TaskGraph, prefix: &str, out: &mut Vec<(String, String, bool)>) {
    for task in &graph.tasks {
        let path = format!("{prefix}{}", task.name.name);
        out.push((
            path.clone(),
            task.name.name.to_string(),
            task.loop_node.is_some(),
        ));
        if let Some(l) = &task.loop_node {
            task_paths(&l.body, &format!("{path}/"), out);
        }
    }
}

fn channel_count(graph: &TaskGraph) -> usize {
    graph.channels.len()
        + graph
            .tasks
            .iter()
            .filter_map(|t| t.loop_node.as_ref())
            .map(|l| channel_count(&l.body))
            .sum::<usize>()
}

/// Coordinates are written with one decimal: a sum of rounded numbers may be
/// off by this much.
const SLACK: f64 = 0.2;

/// Checks the picture of `graph` against the model; gives it for more checks.
fn check(graph: &TaskGraph, what: &str) -> Picture {
    let svg = to_svg(graph);
    let pic = read_picture(&svg);
    let mut tasks = Vec::new();
    task_paths(graph, "", &mut tasks);
    for (path, name, is_loop) in &tasks {
        let shape = pic
            .shapes
            .get(path)
            .unwrap_or_else(|| panic!("{what}: no node for task {path}"));
        if *is_loop {
            assert_eq!(shape.class, "cluster", "{what}: {path}");
            assert!(
                shape
                    .texts
                    .first()
                    .is_some_and(|t| t.starts_with(name.as_str())),
                "{what}: cluster {path} titled {:?}",
                shape.texts
            );
        } else {
            assert!(shape.class.starts_with("node "), "{what}: {path}");
            assert_eq!(shape.texts.first(), Some(name), "{what}: {path}");
        }
    }
    // Boxes do not overlap (sorted by x, compared while they can meet).
    let mut boxes: Vec<(&String, Box2)> = pic
        .shapes
        .iter()
        .filter(|(_, s)| s.class.starts_with("node "))
        .map(|(p, s)| (p, s.bounds))
        .collect();
    boxes.sort_by(|a, b| a.1.x.total_cmp(&b.1.x).then(a.0.cmp(b.0)));
    for i in 0..boxes.len() {
        for j in i + 1..boxes.len() {
            if boxes[j].1.x >= boxes[i].1.x + boxes[i].1.w {
                break;
            }
            assert!(
                !boxes[i].1.overlaps(&boxes[j].1),
                "{what}: {} {:?} overlaps {} {:?}",
                boxes[i].0,
                boxes[i].1,
                boxes[j].0,
                boxes[j].1
            );
        }
    }
    // Clusters hold what is drawn in them; ports sit on their border.
    for (path, shape) in &pic.shapes {
        assert!(
            pic.view.contains(&shape.bounds, 0.0),
            "{what}: {path} outside the view box"
        );
        let Some(cluster) = parent(path) else {
            continue;
        };
        let outer = pic
            .shapes
            .get(cluster)
            .unwrap_or_else(|| panic!("{what}: {path} has no cluster {cluster}"));
        assert_eq!(outer.class, "cluster", "{what}: {cluster}");
        assert!(
            outer.bounds.contains(&shape.bounds, SLACK),
            "{what}: cluster {cluster} {:?} does not contain {path} {:?}",
            outer.bounds,
            shape.bounds
        );
        if shape.class == "port" {
            let b = outer.bounds;
            let x = shape.bounds.x;
            assert!(
                (x - b.x).abs() < SLACK || (x - b.x - b.w).abs() < SLACK,
                "{what}: port {path} not on the border of {cluster}"
            );
        }
    }
    // Edges start at their tail's node and end at their head's.
    for edge in &pic.edges {
        for (end, point) in [(&edge.from, edge.start), (&edge.to, edge.end)] {
            let shape = pic
                .shapes
                .get(end)
                .unwrap_or_else(|| panic!("{what}: edge end {end} is not drawn"));
            let d = shape.bounds.distance(point.0, point.1);
            assert!(
                d < SLACK,
                "{what}: edge {} → {} ends {d} away from {end}",
                edge.from,
                edge.to
            );
        }
        assert!(pic.view.distance(edge.start.0, edge.start.1) == 0.0);
    }
    let data = pic.edges.iter().filter(|e| e.class == "edge data").count();
    assert_eq!(data, channel_count(graph), "{what}: one edge per channel");
    assert_eq!(svg, to_svg(graph), "{what}: the same bytes twice");
    pic
}

fn load(path: &str) -> TaskGraph {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    load_task_graph(FileId(0), &text)
        .0
        .unwrap_or_else(|| panic!("{path} loads"))
}

/// The `.xml` files of a folder of the repository (`examples/taskgraphs`,
/// `tests/data/sdf3`).
fn in_repository(dir: &str) -> Vec<String> {
    let dir = format!("{}/../{dir}", env!("CARGO_MANIFEST_DIR"));
    let mut paths: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .filter_map(|e| e.ok())
        .map(|e| e.path().to_string_lossy().into_owned())
        .filter(|p| p.ends_with(".xml"))
        .collect();
    paths.sort();
    paths
}

fn example(name: &str) -> TaskGraph {
    load(&format!(
        "{}/../examples/taskgraphs/{name}.taskgraph.xml",
        env!("CARGO_MANIFEST_DIR")
    ))
}

#[test]
fn every_reference_example_is_drawn() {
    let paths = in_repository("examples/taskgraphs");
    assert!(paths.len() >= 8, "{paths:?}");
    for path in paths {
        check(&load(&path), &path);
    }
}

#[test]
fn every_sdf3_benchmark_is_drawn() {
    let paths = in_repository("tests/data/sdf3");
    assert_eq!(paths.len(), 11, "{paths:?}");
    for path in paths {
        check(&load(&path), &path);
    }
}

#[test]
fn data_loop_picture() {
    insta::assert_snapshot!(to_svg(&example("data_loop")));
}

#[test]
fn rates_and_initial_samples_are_written_on_channels() {
    let pic = check(&example("kmeans"), "kmeans");
    let edge = |from: &str, to: &str| {
        pic.edges
            .iter()
            .find(|e| e.from == from && e.to == to)
            .unwrap_or_else(|| panic!("no edge {from} → {to}"))
    };
    // ReadPoints produces 16 per firing into the loop's port.
    let e = edge("ReadPoints", "Converge.pts");
    assert_eq!(e.labels, ["16", "16"]);
    // Inside Assign, its distributing port hands one sample per iteration.
    let e = edge("Converge/Assign.pts", "Converge/Assign/Nearest");
    assert_eq!(e.labels, ["1", "1"]);
    // The feedback holds one initial sample, drawn against the flow: its
    // head (Select) is left of its tail.
    let e = edge("Converge/ReplaceCenter", "Converge/Select");
    assert_eq!(e.labels, ["1", "1", "●"]);
    assert!(e.end.0 < e.start.0, "{:?} → {:?}", e.start, e.end);
    // Nested clusters.
    assert_eq!(pic.shapes["Converge/Assign"].class, "cluster");
    assert_eq!(
        pic.shapes["Converge/Assign"].texts[0],
        "Assign (D-loop × 16)"
    );
    // Data flows left to right.
    let x = |p: &str| pic.shapes[p].bounds.x;
    assert!(x("ReadPoints") < x("Converge") && x("Converge") < x("Output"));
    assert!(x("Converge/Select") < x("Converge/Assign"));
    assert!(x("Converge/Assign") < x("Converge/ReplaceCenter"));
}

#[test]
fn libraries_and_multicast_groups_are_drawn() {
    let pic = check(&example("robot_shared_info"), "robot_shared_info");
    assert_eq!(pic.shapes["library ColorList"].class, "node library");
    assert_eq!(pic.shapes["ControlTask"].class, "node control");
    assert_eq!(
        pic.shapes["multicast obstacle_alert"].class,
        "node multicast"
    );
    let call = pic
        .edges
        .iter()
        .find(|e| e.class == "edge call")
        .expect("a library call");
    assert_eq!(
        (call.from.as_str(), call.to.as_str()),
        ("ControlTask", "library ColorList")
    );
    assert_eq!(call.labels, ["colors"]);
    let multicast: Vec<(&str, &str)> = pic
        .edges
        .iter()
        .filter(|e| e.class == "edge multicast")
        .map(|e| (e.from.as_str(), e.to.as_str()))
        .collect();
    assert_eq!(
        multicast,
        [
            ("ControlTask", "multicast obstacle_alert"),
            ("multicast obstacle_alert", "ControlTask")
        ]
    );
}

/// A graph in our format from its inside.
fn graph_of(body: &str) -> TaskGraph {
    let text = format!("<TaskGraph name=\"t\">{body}</TaskGraph>");
    load_task_graph(FileId(0), &text).0.expect("loads")
}

#[test]
fn connections_leaving_a_loop_pass_its_border() {
    let g = graph_of(concat!(
        "<Task name=\"A\"><Port name=\"o\" dir=\"out\"/></Task>",
        "<Library name=\"Lib\"><Function name=\"f\"/></Library>",
        "<Loop name=\"L\" type=\"D\" loopCount=\"2\">",
        "<Port name=\"i\" dir=\"in\" kind=\"distributing\" outerRate=\"2\" innerRate=\"1\"/>",
        "<TaskGraph><Task name=\"B\"><Port name=\"i\" dir=\"in\"/>",
        "<LibraryMasterPort name=\"lib\" library=\"Lib\" calls=\"f\"/>",
        "<MulticastPort name=\"w\" dir=\"out\" group=\"news\"/></Task>",
        "<Channel src=\"L.i\" dst=\"B.i\"/></TaskGraph></Loop>",
        "<Task name=\"R\"><MulticastPort name=\"r\" dir=\"in\" group=\"news\"/></Task>",
        "<Channel src=\"A.o\" dst=\"L.i\"/>",
    ));
    let pic = check(&g, "relays");
    let ends = |class: &str| -> Vec<(String, String)> {
        pic.edges
            .iter()
            .filter(|e| e.class == class)
            .map(|e| (e.from.clone(), e.to.clone()))
            .collect()
    };
    assert_eq!(
        ends("edge call"),
        [
            ("L/B".to_string(), "L.library Lib out".to_string()),
            ("L.library Lib out".to_string(), "library Lib".to_string()),
        ]
    );
    assert_eq!(pic.shapes["L.library Lib out"].class, "relay");
    assert_eq!(ends("edge multicast").len(), 3);
}

#[test]
fn odd_graphs_are_drawn() {
    // Empty.
    let pic = check(&graph_of(""), "empty");
    assert!(pic.shapes.is_empty());
    // Self-loops, parallel channels, a second component, a loop whose
    // output feeds its own input, and an empty loop.
    let g = graph_of(concat!(
        "<Task name=\"A\"><Port name=\"o\" dir=\"out\"/><Port name=\"i\" dir=\"in\"/>",
        "<Port name=\"o2\" dir=\"out\" rate=\"3\"/><Port name=\"i2\" dir=\"in\" rate=\"3\"/></Task>",
        "<Task name=\"B\"><Port name=\"i\" dir=\"in\"/><Port name=\"j\" dir=\"in\"/></Task>",
        "<Task name=\"Lonely\"/>",
        "<Loop name=\"L\" type=\"C\" loopCount=\"3\">",
        "<Port name=\"i\" dir=\"in\" kind=\"broadcasting\"/><Port name=\"o\" dir=\"out\"/>",
        "<TaskGraph><Task name=\"X\"><Port name=\"i\" dir=\"in\"/><Port name=\"o\" dir=\"out\"/></Task>",
        "<Channel src=\"L.i\" dst=\"X.i\"/><Channel src=\"X.o\" dst=\"L.o\"/></TaskGraph></Loop>",
        "<Loop name=\"E\" type=\"D\" loopCount=\"1\"><TaskGraph/></Loop>",
        "<Channel src=\"A.o\" dst=\"A.i\" initialTokens=\"2\"/>",
        "<Channel src=\"A.o2\" dst=\"A.i2\" initialTokens=\"3\"/>",
        "<Channel src=\"A.o\" dst=\"B.i\"/><Channel src=\"A.o\" dst=\"B.j\"/>",
        "<Channel src=\"L.o\" dst=\"L.i\" initialTokens=\"1\"/>",
    ));
    let pic = check(&g, "odd");
    assert!(pic.shapes.contains_key("Lonely") && pic.shapes.contains_key("E"));
    // Special characters in names are escaped (SDF3 names are free text).
    let g = load_task_graph(
        FileId(0),
        concat!(
            "<sdf3 type=\"sdf\"><applicationGraph><sdf name=\"x&amp;y\">",
            "<actor name=\"a&lt;b&gt;&amp;&quot;c&apos;\"><port name=\"p\" type=\"out\" rate=\"1\"/></actor>",
            "<actor name=\"d\"><port name=\"q\" type=\"in\" rate=\"1\"/></actor>",
            "<channel name=\"c\" srcActor=\"a&lt;b&gt;&amp;&quot;c&apos;\" srcPort=\"p\" dstActor=\"d\" dstPort=\"q\"/>",
            "</sdf></applicationGraph></sdf3>"
        ),
    )
    .0
    .expect("loads");
    let pic = check(&g, "escaping");
    assert!(pic.shapes.contains_key("a<b>&\"c'"));
}

#[test]
fn graphs_with_errors_are_drawn_with_placeholders() {
    // Ends naming no task or no port: the loader keeps the channels (E064).
    let text = concat!(
        "<TaskGraph name=\"t\"><Task name=\"A\"><Port name=\"o\" dir=\"out\"/></Task>",
        "<Loop name=\"L\" type=\"D\" loopCount=\"2\"><Port name=\"i\" dir=\"in\"/>",
        "<TaskGraph><Task name=\"B\"><Port name=\"i\" dir=\"in\"/></Task>",
        "<Channel src=\"L.nope\" dst=\"B.i\"/><Channel src=\"Ghost.o\" dst=\"B.i\"/></TaskGraph></Loop>",
        "<Channel src=\"A.o\" dst=\"Nobody.i\"/><Channel src=\"A.zz\" dst=\"L.other\"/>",
        "<Channel src=\"L.i\" dst=\"A.o\"/></TaskGraph>",
    );
    let (graph, diags) = load_task_graph(FileId(0), text);
    assert!(diags.iter().any(|d| d.is_error()));
    let graph = graph.expect("loads with errors");
    let pic = check(&graph, "errors");
    assert_eq!(pic.shapes["Nobody"].class, "node missing");
    assert_eq!(pic.shapes["L/Ghost"].class, "node missing");
    assert_eq!(pic.shapes["L.nope"].class, "port");
    assert_eq!(pic.shapes["L.other"].class, "port");
}

/// The benches' generated graph: a chain of `n` multirate tasks, each with a
/// self-loop, closed by a feedback channel.
fn chain(n: usize) -> TaskGraph {
    let mut body = String::new();
    for i in 0..n {
        let _ = write!(
            body,
            "<Task name=\"t{i}\"><Port name=\"i\" dir=\"in\"/><Port name=\"o\" dir=\"out\"/><Port name=\"side\" dir=\"out\"/><Port name=\"fromside\" dir=\"in\"/></Task>"
        );
    }
    for i in 0..n {
        let next = (i + 1) % n;
        let tokens = if next == 0 { 4 } else { 0 };
        let _ = write!(
            body,
            "<Channel src=\"t{i}.o\" dst=\"t{next}.i\" initialTokens=\"{tokens}\"/><Channel src=\"t{i}.side\" dst=\"t{i}.fromside\" initialTokens=\"1\"/>"
        );
    }
    graph_of(&body)
}

#[test]
fn a_thousand_tasks_are_drawn() {
    let g = chain(1000);
    let pic = check(&g, "chain");
    assert_eq!(pic.shapes.len(), 1000);
}

/// A random graph of our format: tasks with one input and one output port
/// each, channels between any two (self-loops and parallel ones included),
/// some in a loop.
fn random_graph(tasks: usize, channels: &[(usize, usize, u8)], in_loop: usize) -> TaskGraph {
    let task = |i: usize| {
        format!(
            "<Task name=\"t{i}\"><Port name=\"i\" dir=\"in\"/><Port name=\"o\" dir=\"out\"/></Task>"
        )
    };
    let mut body = String::new();
    let inner = in_loop.min(tasks);
    for i in inner..tasks {
        body.push_str(&task(i));
    }
    let mut outer_channels = String::new();
    let mut inner_channels = String::new();
    for &(a, b, tokens) in channels {
        let (a, b) = (a % tasks.max(1), b % tasks.max(1));
        if tasks == 0 {
            break;
        }
        let channel = |s: &str, d: &str| {
            format!("<Channel src=\"{s}\" dst=\"{d}\" initialTokens=\"{tokens}\"/>")
        };
        match (a < inner, b < inner) {
            (true, true) => {
                inner_channels.push_str(&channel(&format!("t{a}.o"), &format!("t{b}.i")))
            }
            (false, false) => {
                outer_channels.push_str(&channel(&format!("t{a}.o"), &format!("t{b}.i")))
            }
            (true, false) => {
                inner_channels.push_str(&channel(&format!("t{a}.o"), "L.out"));
                outer_channels.push_str(&channel("L.out", &format!("t{b}.i")));
            }
            (false, true) => {
                outer_channels.push_str(&channel(&format!("t{a}.o"), "L.in"));
                inner_channels.push_str(&channel("L.in", &format!("t{b}.i")));
            }
        }
    }
    if inner > 0 {
        body.push_str("<Loop name=\"L\" type=\"C\" loopCount=\"2\"><Port name=\"in\" dir=\"in\" kind=\"broadcasting\"/><Port name=\"out\" dir=\"out\"/><TaskGraph>");
        for i in 0..inner {
            body.push_str(&task(i));
        }
        body.push_str(&inner_channels);
        body.push_str("</TaskGraph></Loop>");
    }
    body.push_str(&outer_channels);
    graph_of(&body)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn random_graphs_are_drawn(
        tasks in 0usize..14,
        channels in proptest::collection::vec((0usize..14, 0usize..14, 0u8..3), 0..30),
        in_loop in 0usize..5,
    ) {
        let g = random_graph(tasks, &channels, in_loop);
        check(&g, "random");
    }
}

/// The picture of `g` with its analysis: the paths of the nodes drawn as
/// deadlocked, and the ends of the channels drawn so.
fn deadlock_marks(g: &TaskGraph) -> (Vec<String>, Vec<(String, String)>) {
    let report = crate::taskgraph::analysis::analyze(g);
    let pic = read_picture(&super::to_svg_analyzed(g, &report));
    let mut nodes: Vec<String> = pic
        .shapes
        .iter()
        .filter(|(_, s)| s.class.ends_with(" deadlock"))
        .map(|(path, _)| path.clone())
        .collect();
    nodes.sort();
    let mut edges: Vec<(String, String)> = pic
        .edges
        .iter()
        .filter(|e| e.class == "edge data deadlock")
        .map(|e| (e.from.clone(), e.to.clone()))
        .collect();
    edges.sort();
    (nodes, edges)
}

fn pair(a: &str, b: &str) -> (String, String) {
    (a.to_string(), b.to_string())
}

#[test]
fn a_deadlocked_cycle_is_drawn_in_red_and_nothing_else_is() {
    // S feeds the cycle X → Y → X, which has no initial sample; Z hangs off it.
    let g = graph_of(concat!(
        "<Task name=\"S\"><Port name=\"o\" dir=\"out\"/></Task>",
        "<Task name=\"X\"><Port name=\"in\" dir=\"in\"/><Port name=\"fb\" dir=\"in\"/><Port name=\"o\" dir=\"out\"/></Task>",
        "<Task name=\"Y\"><Port name=\"i\" dir=\"in\"/><Port name=\"back\" dir=\"out\"/><Port name=\"o\" dir=\"out\"/></Task>",
        "<Task name=\"Z\"><Port name=\"i\" dir=\"in\"/></Task>",
        "<Channel src=\"S.o\" dst=\"X.in\"/>",
        "<Channel src=\"X.o\" dst=\"Y.i\"/>",
        "<Channel src=\"Y.back\" dst=\"X.fb\"/>",
        "<Channel src=\"Y.o\" dst=\"Z.i\"/>",
    ));
    let (nodes, edges) = deadlock_marks(&g);
    assert_eq!(nodes, ["X", "Y"]);
    assert_eq!(edges, [pair("X", "Y"), pair("Y", "X")]);
    // Without the analysis, or once a sample starts the cycle, nothing is red.
    assert!(!to_svg(&g).contains("deadlock"));
    let fixed = graph_of(concat!(
        "<Task name=\"X\"><Port name=\"fb\" dir=\"in\"/><Port name=\"o\" dir=\"out\"/></Task>",
        "<Task name=\"Y\"><Port name=\"i\" dir=\"in\"/><Port name=\"back\" dir=\"out\"/></Task>",
        "<Channel src=\"X.o\" dst=\"Y.i\"/>",
        "<Channel src=\"Y.back\" dst=\"X.fb\" initialTokens=\"1\"/>",
    ));
    assert_eq!(deadlock_marks(&fixed), (vec![], vec![]));
}

#[test]
fn a_deadlock_inside_a_loop_body_is_marked_in_its_cluster() {
    let g = graph_of(concat!(
        "<Task name=\"A\"><Port name=\"o\" dir=\"out\"/></Task>",
        "<Loop name=\"L\" type=\"D\" loopCount=\"2\">",
        "<Port name=\"i\" dir=\"in\" kind=\"distributing\" outerRate=\"2\" innerRate=\"1\"/>",
        "<TaskGraph>",
        "<Task name=\"B\"><Port name=\"i\" dir=\"in\"/><Port name=\"fb\" dir=\"in\"/><Port name=\"o\" dir=\"out\"/></Task>",
        "<Task name=\"C\"><Port name=\"i\" dir=\"in\"/><Port name=\"back\" dir=\"out\"/></Task>",
        "<Channel src=\"L.i\" dst=\"B.i\"/>",
        "<Channel src=\"B.o\" dst=\"C.i\"/>",
        "<Channel src=\"C.back\" dst=\"B.fb\"/>",
        "</TaskGraph></Loop>",
        "<Channel src=\"A.o\" dst=\"L.i\"/>",
    ));
    let (nodes, edges) = deadlock_marks(&g);
    assert_eq!(nodes, ["L/B", "L/C"]);
    assert_eq!(edges, [pair("L/B", "L/C"), pair("L/C", "L/B")]);
}
