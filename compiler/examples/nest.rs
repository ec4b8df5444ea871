fn main() {
    let n: usize = std::env::args().nth(1).unwrap().parse().unwrap();
    let kind = std::env::args().nth(2).unwrap();
    let text = match kind.as_str() {
        "if" => {
            let mut t = String::from("{ T: iRobotCreate a }\nT.Action.Go {\n");
            for _ in 0..n {
                t.push_str("if (LOCATION == \"0,0\") {\n");
            }
            t
        }
        "ifc" => {
            let mut t = String::from("{ T: iRobotCreate a }\nT.Action.Go {\n");
            for _ in 0..n {
                t.push_str("if (LOCATION == \"0,0\") {\n");
            }
            for _ in 0..n {
                t.push_str("}\n");
            }
            t.push('}');
            t
        }
        _ => format!(
            "T.Action.Go {{ if ({}x{}) stop() }}",
            "(".repeat(n),
            ")".repeat(n)
        ),
    };
    let t = std::time::Instant::now();
    let p = semo::syntax::parse(semo::diag::FileId(0), &text);
    println!(
        "n={n} {kind}: {:?} diags={}",
        t.elapsed(),
        p.diagnostics.len()
    );
}
