//! The generated benchmark mission, shared by the compiler's and the language
//! server's benches.

use std::fmt::Write;

/// A realistic mission: mixed teams with groups, communication between
/// neighbouring teams, modes with transitions, functions, comments. It
/// checks without a warning: a team going home tells the next one `done`
/// (which the next one's `Hear` compares with), so the editor's benches
/// measure an edit's check, not 154 W020 warnings sent with each one.
pub fn generate(teams: usize) -> String {
    let mut m = String::from("# Generated benchmark mission\n{\n");
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
  else if(Team{prev}.Status == "done") throw finish
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

Team{t}.Action.Hide{{
  if(DISTANCE > 30){{
    go_forward()
  }} else {{
    turn_left()
  }}
  stop()
}} repeat(LOCATION != "0,0")

Team{t}.Action.Return{{
  report_home()
  send(Team{next}, Team{t}.Status = "done")
}}

Team{t}.PATROL{{ set(Listen, Hear); set(Report, Tell); set(Action, Patrol) }}
Team{t}.HIDE{{ set(Listen, Hear); set(Report, OFF); set(Action, Hide, timeout = 30 SEC) }}
Team{t}.HOME{{ set(Listen, OFF); set(Report, OFF); set(Action, Return) }}
Team{t}.main{{
  case (PATROL):
    catch (hide): mode = HIDE
    catch (finish): mode = HOME
  case (HIDE):
    catch (resume): mode = PATROL
  default: mode = PATROL
}}

"#
        )
        .unwrap();
    }
    m
}

/// Issue 36's swarm mission: one team of `robots` TurtleBots split at run
/// time into three rooms of counted groups (minimums of 30%, 30% and 20%
/// of the team), each room split again into two searchers and the robots
/// at its door, every second. Every robot sends a heartbeat to all the
/// others every 200 ms, so almost every event of a run is a heartbeat
/// heard. `benches/fixtures/nested_groups.mission` is this of 200 robots.
#[allow(dead_code)] // the simulator's bench and scaling test only
pub fn nested_groups(robots: usize) -> String {
    let (room, small) = (robots * 3 / 10, robots / 5);
    format!(
        r#"# Benchmark input (issue 36's performance target, `cargo bench --bench
# simulate`): one team of {robots} robots split at run time into three rooms of
# counted groups, each room split again into searchers and robots at its door.
# Every robot sends a heartbeat to the other {others} every 200 ms, so almost all of
# a run's events are heartbeat receipts.
{{
  Crew: Turtlebot3_Burger tb[{robots}]
}}

def room(DOOR) {{
  [[
    group(Searcher, min = 2) {{
      move(DOOR)
    }}
    others {{
      standby()
    }}
  ]]
}}

Crew.Work.Rooms {{
  [[
    group(Room1, min = {room}) {{
      room("1,1")
    }}
    group(Room2, min = {room}) {{
      room("5,1")
    }}
    group(Room3, min = {small}) {{
      room("9,1")
    }}
  ]]
}} repeat(1 SEC)

Crew.ROOMS {{
  set(Work, Rooms)
}}

Crew.main {{
  default: mode = ROOMS
}}
"#,
        others = robots - 1
    )
}
