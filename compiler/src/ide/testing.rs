//! Helpers for the unit tests of the IDE features: a mission analysed against
//! the built-in catalog (and optionally one catalog file), and readable spans.

use crate::Analysis;
use crate::catalog::{Catalog, CatalogSource, load_catalog};
use crate::diag::FileId;
use crate::span::Span;
use crate::text::{ColumnUnit, LineIndex};

pub(crate) struct Fixture {
    pub text: String,
    pub analysis: Analysis,
    pub catalog: Catalog,
}

impl Fixture {
    pub const FILE: FileId = FileId(0);
    pub const CATALOG_FILE: FileId = FileId(1);

    pub fn new(text: &str) -> Fixture {
        Fixture::build(text, &[])
    }

    pub fn with_catalog(text: &str, xml: &str) -> Fixture {
        Fixture::build(
            text,
            &[CatalogSource {
                file: Fixture::CATALOG_FILE,
                text: xml,
                base_dir: None,
            }],
        )
    }

    fn build(text: &str, sources: &[CatalogSource<'_>]) -> Fixture {
        let (catalog, diagnostics) = load_catalog(sources);
        assert!(diagnostics.is_empty(), "{diagnostics:#?}");
        let analysis = crate::check_source(Fixture::FILE, text, &catalog);
        Fixture {
            text: text.to_string(),
            analysis,
            catalog,
        }
    }

    /// The offset where `marker` starts; it must occur exactly once.
    pub fn offset_of(&self, marker: &str) -> usize {
        let mut found = self.text.match_indices(marker);
        let (offset, _) = found.next().unwrap_or_else(|| panic!("no `{marker}`"));
        assert!(found.next().is_none(), "`{marker}` occurs twice");
        offset
    }

    /// One-based line and column (in bytes) of an offset.
    pub fn line_col(&self, offset: usize) -> (u32, u32) {
        line_col(&self.text, offset)
    }
}

fn line_col(text: &str, offset: usize) -> (u32, u32) {
    let lc = LineIndex::new(text).line_col(text, offset, ColumnUnit::Utf8);
    (lc.line + 1, lc.col + 1)
}

/// `line:col text` of each span, comma-separated.
pub(crate) fn spans_text(text: &str, spans: impl IntoIterator<Item = Span>) -> String {
    spans
        .into_iter()
        .map(|s| {
            let (line, col) = line_col(text, s.start);
            format!("{line}:{col} {}", &text[s.range()])
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// A realistic mission of about 50 lines per team (as the throughput bench):
/// groups, communication between neighbouring teams, modes, a function.
pub(crate) fn large_mission(teams: usize) -> String {
    use std::fmt::Write;
    let mut m = String::from("# Generated mission (한국어 주석)\n{\n");
    for t in 0..teams {
        writeln!(
            m,
            "  Team{t}: Turtlebot3_Burger tb{t}[3], Ev3_Robot ev{t}[2], iRobotCreate cr{t}"
        )
        .unwrap();
    }
    m.push_str("}\n\ndef report_home {\n  move(\"0,0\")\n  standby()\n}\n\n");
    for t in 0..teams {
        let next = (t + 1) % teams;
        let prev = (t + teams - 1) % teams;
        write!(
            m,
            r#"# ----- Team{t} -----
Team{t}.Listen.Hear{{
  receive(Team{prev}, Team{prev}.Status)
  subscribe(Team{t}, Team{t}.Alarm)
  if(Team{t}.Alarm == DARK) throw hide
  else if(Team{prev}.Status == "done 😀") throw finish
  else throw resume
}} repeat(500 MSEC)

Team{t}.Report.Tell{{
  send(Team{next}, Team{t}.Status = "working")
  send(USER, Team{t}.LOCATION)
  [[
    leader(instance of Turtlebot3_Burger){{
      light_on()
      publish(Team{t}, Team{t}.Alarm = BRIGHT)
    }}
  ]]
}} repeat(1 SEC)

Team{t}.Action.Patrol{{
  [[
    group(instance of Turtlebot3_Burger){{
      loop(2 SEC){{
        if(Team{t}.LIGHTNESS < 200 and BATTERY > 20)
          publish(Team{t}, Team{t}.Alarm = DARK)
      }}
    }}
    group(capable of color_sensor){{
      search(colored_paper)
      scatter()
    }}
    others{{
      move("3,3"), timeout = 10 SEC
      move("0,3")
    }}
  ]]
}} repeat()

Team{t}.Action.Return{{
  report_home()
}}

Team{t}.PATROL{{ set(Listen, Hear); set(Report, Tell); set(Action, Patrol) }}
Team{t}.HOME{{ set(Listen, OFF); set(Report, OFF); set(Action, Return) }}
Team{t}.main{{
  case (PATROL):
    catch (hide): mode = PATROL
    catch (finish): mode = HOME
  case (HOME):
    catch (resume): mode = PATROL
  default: mode = PATROL
}}

"#
        )
        .unwrap();
    }
    m
}
