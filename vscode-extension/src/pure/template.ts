// The skeleton of a new mission (spec §6). The same text as
// `MISSION_TEMPLATE` in compiler/src/ide/mission/snippets.rs, which the server's
// completion offers; a unit test keeps the two equal.

export const MISSION_TEMPLATE = `# 1. Team formation:  TeamName: RobotType robot_name
{
}
# 2. Behaviour of each team
# Part 1. Composite services:  TeamName.PlanName.ServiceName { ... } repeat(...)
# Part 2. Modes:               TeamName.ModeName { set(PlanName, ServiceName or OFF) }
# Part 3. Mode changes:        TeamName.main { case (Mode): catch (event): mode = Other  default: mode = Mode }
`;

/** The template as a snippet: the cursor inside the formation braces. */
export function missionTemplateSnippet(): string {
  const escape = (text: string) => text.replace(/[\\$}]/g, (c) => `\\${c}`);
  const at = MISSION_TEMPLATE.indexOf('{\n}');
  const before = MISSION_TEMPLATE.slice(0, at);
  const after = MISSION_TEMPLATE.slice(at + 3);
  return `${escape(before)}{\n\t$0\n}${escape(after)}`;
}
