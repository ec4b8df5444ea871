//! The MQTT topics of a mission, as `semo_mqtt.c` names them: the broker's
//! ACL (`broker.rs`) must allow exactly what the robots use, so this mirrors
//! the C functions `mission_name`, `append_level` and `topic_of`.

/// The mission's name in topics: the file name without `.mission`, at most
/// 63 bytes (the runtime's buffer).
pub fn mission(file_name: &str) -> String {
    let name = if file_name.is_empty() {
        "mission"
    } else {
        file_name
    };
    let bytes: Vec<u8> = name.bytes().take(63).collect();
    let name = String::from_utf8_lossy(&bytes).into_owned();
    // As C's `strstr`: the first `.mission`, cut only where it ends the name.
    match name.find(".mission") {
        Some(at) if at > 0 && at + 8 == name.len() => name[..at].to_string(),
        _ => name,
    }
}

/// One topic level: the characters MQTT gives a meaning to become `_`.
pub fn level(name: &str) -> String {
    name.replace(['/', '+', '#'], "_")
}

/// `semo/<mission>/<team>/<key>`: a message to every robot of `team`.
pub fn to_team(mission: &str, team: &str, key: &str) -> String {
    format!("semo/{}/{}/{}", level(mission), level(team), level(key))
}

/// `semo/<mission>/<team>/<robot>/<key>`: a message to one robot.
pub fn to_robot(mission: &str, team: &str, robot: &str, key: &str) -> String {
    format!(
        "semo/{}/{}/{}/{}",
        level(mission),
        level(team),
        level(robot),
        level(key)
    )
}

/// `semo/<mission>/status/<robot>`: the robot's retained status.
pub fn status(mission: &str, robot: &str) -> String {
    format!("semo/{}/status/{}", level(mission), level(robot))
}

/// `semo/<mission>/<team>/<team>.__alive`: where the robots of `program`'s
/// team publish their heartbeats for leader elections (when
/// `program.control.heartbeat`).
pub fn heartbeats(program: &crate::refine::RobotProgram) -> String {
    to_team(
        &mission(&program.mission),
        &program.team,
        &crate::codegen::files::alive_key(program),
    )
}

#[cfg(test)]
mod tests {
    #[test]
    fn names_become_levels_as_the_runtime_makes_them() {
        assert_eq!(super::mission("scouting.mission"), "scouting");
        assert_eq!(super::mission(".mission"), ".mission");
        assert_eq!(super::mission(""), "mission");
        assert_eq!(
            super::to_team("a+b.mission", "T#", "K/x"),
            "semo/a_b.mission/T_/K_x"
        );
        assert_eq!(
            super::to_robot("m", "SlaveTeam", "ti", "USER.RC_CMD"),
            "semo/m/SlaveTeam/ti/USER.RC_CMD"
        );
        assert_eq!(super::mission(&"x".repeat(80)).len(), 63);
    }
}
