//! Document synchronisation through the protocol: diagnostics on open and
//! change, edits applied in order under bursts, and both position encodings.

mod support;

use semo_server::harness::TestClient;
use serde_json::{Value, json};
use support::position_of;

const MISSION: &str = "{\n  Team: iRobotCreate r\n}\nTeam.Plan.Go{\n  move(\"1,1\")\n} repeat()\nTeam.M{ set(Plan, Go) }\nTeam.main{ default: mode = M }\n";

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn diagnostics_are_published_on_open_and_cleared_after_a_fix() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let broken = MISSION.replace("move(", "mvoe(");
    client.open("file:///t/a.mission", &broken).await;
    let diags = client.diagnostics("file:///t/a.mission", Some(1)).await;
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0]["code"], "E024");
    assert_eq!(diags[0]["source"], "semo");
    assert!(
        diags[0]["message"]
            .as_str()
            .unwrap()
            .contains("did you mean `move`?"),
        "{}",
        diags[0]["message"]
    );
    assert_eq!(diags[0]["data"]["suggestion"], "move");
    assert_eq!(
        diags[0]["range"],
        json!({ "start": { "line": 4, "character": 2 }, "end": { "line": 4, "character": 6 } })
    );

    client
        .notify(
            "textDocument/didChange",
            json!({
                "textDocument": { "uri": "file:///t/a.mission", "version": 2 },
                "contentChanges": [{
                    "range": { "start": { "line": 4, "character": 3 }, "end": { "line": 4, "character": 5 } },
                    "text": "ov"
                }]
            }),
        )
        .await;
    assert_eq!(
        client.diagnostics("file:///t/a.mission", Some(2)).await,
        Vec::<Value>::new()
    );

    client
        .notify(
            "textDocument/didClose",
            json!({ "textDocument": { "uri": "file:///t/a.mission" } }),
        )
        .await;
    assert_eq!(
        client.diagnostics("file:///t/a.mission", None).await,
        Vec::<Value>::new()
    );
    client.shutdown().await;
}

/// A tiny deterministic generator, so that a failure replays.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self, bound: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) as usize) % bound.max(1)
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_burst_of_a_thousand_edits_ends_in_the_expected_text_and_diagnostics() {
    let mut client = TestClient::start();
    client.initialize(&["utf-16"], None).await;
    let uri = "file:///t/burst.mission";
    let start = format!("# 한국어 주석 😀\n{MISSION}");
    client.open(uri, &start).await;

    // The client's model of the text; every edit is applied to it as well.
    let mut text = start.clone();
    let mut rng = Lcg(7);
    let alphabet = ['a', 'e', '(', ')', ' ', '\n', '한', '😀', '"', '{', '}'];
    let mut version = 1;
    for i in 0..1000 {
        version += 1;
        let boundaries: Vec<usize> = text
            .char_indices()
            .map(|(i, _)| i)
            .chain([text.len()])
            .collect();
        let at = boundaries[rng.next(boundaries.len())];
        let (end, insert) = if rng.next(3) == 0 && at < text.len() {
            // Delete one character.
            let len = text[at..].chars().next().unwrap().len_utf8();
            (at + len, String::new())
        } else {
            (at, alphabet[rng.next(alphabet.len())].to_string())
        };
        let change = json!({
            "range": { "start": position_of(&text, at), "end": position_of(&text, end) },
            "text": insert,
        });
        text.replace_range(at..end, &insert);
        client
            .notify(
                "textDocument/didChange",
                json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": [change] }),
            )
            .await;
        if i % 25 == 0 {
            // Requests interleaved with the burst see some consistent version.
            let seen = client
                .request("semo/viewFileText", json!({ "uri": uri }))
                .await
                .expect("the document is known");
            assert!(seen.is_string());
        }
    }

    let final_text = client
        .request("semo/viewFileText", json!({ "uri": uri }))
        .await
        .unwrap();
    assert_eq!(final_text.as_str().unwrap(), text);
    let after_burst = client.diagnostics(uri, Some(version)).await;

    // A from-scratch check of the expected text, in a fresh document.
    let fresh = "file:///t/fresh.mission";
    client.open(fresh, &text).await;
    let from_scratch = client.diagnostics(fresh, Some(1)).await;
    assert_eq!(after_burst, from_scratch);
    assert!(!from_scratch.is_empty(), "random edits break the mission");
    client.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn positions_use_utf8_when_offered_else_utf16() {
    // `mvoe` comes after a Korean comment and an emoji string on its line.
    let text = "{\n  Team: iRobotCreate r\n}\nTeam.Plan.Go{\n  say(\"😀\") mvoe(\"1,1\") # 한국어\n} repeat()\nTeam.M{ set(Plan, Go) }\nTeam.main{ default: mode = M }\n";
    let line = text.lines().nth(4).unwrap();
    let byte_col = line.find("mvoe").unwrap();
    let utf16_col = line[..byte_col].encode_utf16().count();
    assert_ne!(byte_col, utf16_col);
    for (offered, kind, col) in [
        (&["utf-8", "utf-16"][..], "utf-8", byte_col),
        (&["utf-16"][..], "utf-16", utf16_col),
        (&[][..], "utf-16", utf16_col),
    ] {
        let mut client = TestClient::start();
        let init = client.initialize(offered, None).await;
        assert_eq!(init["capabilities"]["positionEncoding"], kind);
        client.open("file:///t/enc.mission", text).await;
        let diags = client.diagnostics("file:///t/enc.mission", Some(1)).await;
        let mvoe = diags
            .iter()
            .find(|d| d["message"].as_str().unwrap().contains("mvoe"))
            .unwrap_or_else(|| panic!("{diags:#?}"));
        assert_eq!(
            mvoe["range"]["start"],
            json!({ "line": 4, "character": col })
        );
        assert_eq!(
            mvoe["range"]["end"],
            json!({ "line": 4, "character": col + 4 })
        );

        // An edit after the emoji, in the negotiated encoding, fixes the call.
        client
            .notify(
                "textDocument/didChange",
                json!({
                    "textDocument": { "uri": "file:///t/enc.mission", "version": 2 },
                    "contentChanges": [{
                        "range": { "start": { "line": 4, "character": col + 1 }, "end": { "line": 4, "character": col + 3 } },
                        "text": "ov"
                    }]
                }),
            )
            .await;
        let fixed = client.diagnostics("file:///t/enc.mission", Some(2)).await;
        assert!(
            fixed
                .iter()
                .all(|d| !d["message"].as_str().unwrap().contains("mvoe")),
            "{kind}: {fixed:#?}"
        );
        client.shutdown().await;
    }
}
