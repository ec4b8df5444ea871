//! The built-in catalog: the robots of the seed's experiments, embedded as a
//! catalog file (`builtin.robot.xml`) so that `semo check` works on a bare mission.

use super::Catalog;
use super::xml::parse_catalog;
use crate::diag::FileId;
use std::sync::OnceLock;

/// The file id of the built-in catalog: origins of built-in entries point into
/// [`BUILTIN_SOURCE`] with this id.
pub const BUILTIN_FILE: FileId = FileId(u32::MAX);

/// The text of the built-in catalog file.
pub const BUILTIN_SOURCE: &str = include_str!("builtin.robot.xml");

/// The name under which the built-in catalog is shown (hover links, messages).
pub const BUILTIN_NAME: &str = "builtin.robot.xml";

/// The built-in robot types, plus the `USER` pseudo-robot (the operator console).
pub fn builtin_catalog() -> Catalog {
    static CATALOG: OnceLock<Catalog> = OnceLock::new();
    CATALOG
        .get_or_init(|| {
            let parsed = parse_catalog(BUILTIN_FILE, BUILTIN_SOURCE, None);
            debug_assert!(
                parsed.diagnostics.is_empty(),
                "the built-in catalog has errors: {:?}",
                parsed.diagnostics
            );
            let mut catalog = Catalog::from_types(parsed.robots.into_iter().map(|r| r.robot));
            if let Some(user) = parsed.operator {
                catalog.set_user(user.robot);
            }
            catalog
        })
        .clone()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::ValueType;

    #[test]
    fn builtin_file_has_no_diagnostics() {
        let parsed = parse_catalog(BUILTIN_FILE, BUILTIN_SOURCE, None);
        assert!(parsed.diagnostics.is_empty(), "{:#?}", parsed.diagnostics);
        assert_eq!(parsed.robots.len(), 6);
        assert!(parsed.operator.is_some());
    }

    #[test]
    fn every_entry_is_documented() {
        let catalog = builtin_catalog();
        let user = catalog.user().expect("USER pseudo-robot");
        for robot in catalog.types().map(|(_, r)| r).chain(std::iter::once(user)) {
            assert!(!robot.doc.is_empty(), "{} has no doc", robot.name);
            for v in &robot.values {
                assert!(!v.doc.is_empty(), "{}.{} has no doc", robot.name, v.name);
                assert!(
                    matches!(v.implementation, crate::catalog::Implementation::Task(_)),
                    "{}.{} has no task",
                    robot.name,
                    v.name
                );
            }
            for s in &robot.services {
                assert!(!s.doc.is_empty(), "{}.{} has no doc", robot.name, s.name);
                assert!(
                    matches!(s.implementation, crate::catalog::Implementation::Task(_)),
                    "{}.{} has no task",
                    robot.name,
                    s.name
                );
            }
        }
    }

    #[test]
    fn table_facts() {
        let c = builtin_catalog();
        let names: Vec<&str> = c.types().map(|(_, r)| r.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "iRobotCreate",
                "TIEvalbot",
                "NXTLego",
                "Turtlebot3_Burger",
                "Ev3_Robot",
                "VRepQuadrupotor"
            ]
        );
        // USER is not a formation robot type.
        assert!(c.robot("USER").is_none());
        assert!(c.robot("user").is_none());

        let lego = c.robot("lego_robot").expect("alias lego_robot");
        assert_eq!(lego.name, "NXTLego");
        assert_eq!(lego.value("COLOR").map(|v| &v.ty), Some(&ValueType::String));
        let search = lego.service("search").expect("search");
        assert_eq!(search.signature(), "search(target?: string)");
        assert!(lego.has_capability("color_sensor"));
        assert_eq!(lego.platform.clock_mhz, Some(48));
        assert_eq!(lego.platform.memory_kb, Some(64));

        assert_eq!(
            c.robot("TurtlebotBurger").unwrap().name,
            "Turtlebot3_Burger"
        );
        assert_eq!(c.robot("Ev3Robot").unwrap().name, "Ev3_Robot");

        let quad = c.robot("VRepQuadrupotor").unwrap();
        for wheel in [
            "move",
            "go_forward",
            "go_backward",
            "turn_left",
            "turn_right",
        ] {
            assert!(quad.service(wheel).is_none(), "quadruped has {wheel}");
        }
        for s in [
            "stop",
            "process",
            "standby",
            "stand_by",
            "march",
            "turn_back",
        ] {
            assert!(quad.service(s).is_some(), "quadruped lacks {s}");
        }
        assert_eq!(
            quad.value("obstacle").map(|v| &v.ty),
            Some(&ValueType::Bool)
        );

        for (_, robot) in c.types() {
            let standby = robot.service("stand_by").expect("stand_by");
            assert_eq!(standby.name, "standby");
            for v in ["LOCATION", "DISTANCE", "BATTERY"] {
                assert!(robot.value(v).is_some(), "{} lacks {v}", robot.name);
            }
            assert_eq!(robot.value("DISTANCE").unwrap().unit.as_deref(), Some("cm"));
            assert_eq!(
                robot.value("BATTERY").unwrap().unit.as_deref(),
                Some("percent")
            );
            assert!(robot.service("process").unwrap().required_params() == 1);
            assert_eq!(robot.origin.file, BUILTIN_FILE);
        }

        let create = c.robot("iRobotCreate").unwrap();
        assert_eq!(
            create.service("move").unwrap().signature(),
            "move(goal?: location)"
        );
        assert_eq!(
            create.service("follow").unwrap().signature(),
            "follow(object: string)"
        );
        assert_eq!(create.value("CAMERA").unwrap().ty, ValueType::Image);
        assert_eq!(create.platform.cores, Some(4));
        assert!(create.has_capability("vicon"));

        let burger = c.robot("Turtlebot3_Burger").unwrap();
        for s in ["light_on", "light_off", "scatter"] {
            assert!(burger.service(s).is_some());
        }
        assert_eq!(burger.value("LIGHTNESS").unwrap().ty, ValueType::Int);

        let ev3 = c.robot("Ev3_Robot").unwrap();
        assert!(ev3.value("SEARCHEDCOLOR").is_some());
        assert!(ev3.service("scatter").is_some() && ev3.service("spin").is_none());

        let user = c.user().unwrap();
        assert_eq!(user.name, "USER");
        assert_eq!(user.aliases, ["user"]);
        let cmd = user.value("cmd").expect("RC_CMD alias cmd");
        assert_eq!(cmd.name, "RC_CMD");
        assert_eq!(cmd.ty, ValueType::String);
    }

    #[test]
    fn origins_point_at_start_tags() {
        let c = builtin_catalog();
        let robot = c.robot("NXTLego").unwrap();
        let tag = &BUILTIN_SOURCE[robot.origin.span.range()];
        assert_eq!(tag, r#"<Robot type="NXTLego" aliases="lego_robot">"#);
        let color = robot.value("COLOR").unwrap();
        let tag = &BUILTIN_SOURCE[color.origin.span.range()];
        assert!(
            tag.starts_with("<Value name=\"COLOR\"") && tag.ends_with("/>"),
            "{tag}"
        );
    }
}
