// The "Robots (live)" view's tree, from the server's `semo/monitor`
// notifications (docs/live-monitor.md): one node per robot with its state
// and mode, its counted groups, its services per plan below it, the leader
// marked, lost robots marked. Pure: unit-tested without VS Code.

/** A robot as `semo/monitor` sends it. */
export interface LiveRobot {
  robot: string;
  team: string;
  state: string;
  lost: boolean;
  lostBecause?: 'lastWill' | 'silent';
  mode: string | null;
  /** The mission line (1-based) where its mode is written. */
  modeLine?: number | null;
  services: { plan: string; service: string; line?: number | null }[];
  /** Its group at each statement of counted groups, in the mission's order
   * (absent from a server that does not send them). */
  groups?: { group: string; alive: number }[];
  leader: string | null;
  isLeader: boolean;
  battery: number | null;
}

/** The params of one `semo/monitor` notification. */
export interface MonitorView {
  uri: string;
  mission: string;
  broker: string;
  connection: 'connecting' | 'connected' | 'disconnected';
  error: string | null;
  robots: LiveRobot[];
}

export type LiveKind = 'connection' | 'robot' | 'service';

export interface LiveNode {
  id: string;
  kind: LiveKind;
  label: string;
  description: string;
  tooltip: string;
  /** A codicon name (`vscode.ThemeIcon`). */
  icon: string;
  /** A theme colour id for the icon, or none. */
  color?: string;
  children: LiveNode[];
}

/** Why a lost robot is lost, in words. */
function lostWhy(robot: LiveRobot): string {
  switch (robot.lostBecause) {
    case 'lastWill':
      return 'lost: its connection dropped (last will)';
    case 'silent':
      return 'lost: no heartbeat for three periods';
    default:
      return 'lost';
  }
}

function robotNode(view: MonitorView, robot: LiveRobot): LiveNode {
  const parts: string[] = [];
  parts.push(robot.lost ? 'LOST' : robot.state);
  if (robot.mode) {
    parts.push(robot.mode);
  }
  const groups = robot.groups ?? [];
  if (groups.length > 0) {
    parts.push(groups.map((g) => g.group).join(', '));
  }
  if (robot.isLeader) {
    parts.push('★ leader');
  }
  if (robot.battery !== null && robot.battery !== undefined) {
    parts.push(`battery ${robot.battery}`);
  }
  const tooltip = [
    `**${robot.robot}** (team ${robot.team})`,
    '',
    robot.lost ? lostWhy(robot) : `state: ${robot.state}`,
    robot.mode ? `mode: ${robot.mode}` : 'mode: not reported yet',
    robot.leader ? `leader: ${robot.leader}${robot.isLeader ? ' (itself)' : ''}` : '',
    groups.length > 0
      ? `groups: ${groups.map((g) => `${g.group} (${g.alive} alive)`).join(', ')}`
      : '',
  ]
    .filter((line, i) => i < 2 || line !== '')
    .join('\n\n');
  const icon = robot.lost
    ? { icon: 'error', color: 'errorForeground' }
    : robot.state === 'waiting'
      ? { icon: 'watch' }
      : robot.isLeader
        ? { icon: 'star-full', color: 'charts.yellow' }
        : robot.state === 'running'
          ? { icon: 'pass', color: 'testing.iconPassed' }
          : { icon: 'circle-outline' };
  return {
    // VS Code keeps an item's collapsed state by id: a robot gets another id
    // once it has services, so that they show expanded when they first come.
    id: `${view.uri}#${robot.robot}${robot.services.length > 0 ? '#running' : ''}`,
    kind: 'robot',
    label: robot.robot,
    description: parts.join(' · '),
    tooltip,
    ...icon,
    children: robot.services.map((s) => ({
      id: `${view.uri}#${robot.robot}/${s.plan}`,
      kind: 'service' as const,
      label: s.plan,
      description: s.service,
      tooltip: `plan ${s.plan} runs ${s.service}`,
      icon: 'symbol-method',
      children: [],
    })),
  };
}

/** The tree of one monitor: the connection first, then each robot. */
export function buildLiveTree(view: MonitorView): LiveNode[] {
  const down = view.connection === 'disconnected';
  const connection: LiveNode = {
    id: `${view.uri}#connection`,
    kind: 'connection',
    label: view.mission,
    description: `${view.connection} · ${view.broker}`,
    tooltip: down && view.error ? `${view.broker}: ${view.error}` : `${view.broker}: ${view.connection}`,
    icon: down ? 'debug-disconnect' : view.connection === 'connected' ? 'broadcast' : 'loading~spin',
    color: down ? 'errorForeground' : undefined,
    children: [],
  };
  return [connection, ...view.robots.map((r) => robotNode(view, r))];
}

/** Whether a notification's params are a monitor view at all. */
export function isMonitorView(params: unknown): params is MonitorView {
  const p = params as MonitorView | undefined;
  return !!p && typeof p.uri === 'string' && Array.isArray(p.robots);
}

/** A mark on a mission line: the robots in the mode written there, or running the service. */
export interface LiveMark {
  /** 1-based. */
  line: number;
  kind: 'mode' | 'service';
  text: string;
}

/** Robots still taking part: neither lost nor waiting for their first status. */
function active(view: MonitorView): LiveRobot[] {
  return view.robots.filter((r) => !r.lost && r.state !== 'waiting');
}

/**
 * Where the running robots are in the mission text: each mode's line with
 * the robots in that mode, each service's line with the robots running it,
 * in line order (one mark per line and kind).
 */
export function liveMarks(view: MonitorView): LiveMark[] {
  const marks = new Map<string, { line: number; kind: 'mode' | 'service'; robots: string[] }>();
  const add = (line: number | null | undefined, kind: 'mode' | 'service', robot: string) => {
    if (typeof line !== 'number') {
      return;
    }
    const key = `${kind}:${line}`;
    const mark = marks.get(key) ?? { line, kind, robots: [] };
    mark.robots.push(robot);
    marks.set(key, mark);
  };
  for (const robot of active(view)) {
    add(robot.modeLine, 'mode', robot.robot);
    for (const s of robot.services) {
      add(s.line, 'service', robot.robot);
    }
  }
  return [...marks.values()]
    .sort((a, b) => a.line - b.line || a.kind.localeCompare(b.kind))
    .map((m) => ({
      line: m.line,
      kind: m.kind,
      text: `${m.kind === 'mode' ? '◀ in this mode' : '▶ running'}: ${m.robots.join(', ')}`,
    }));
}

/** `text` as a CSS string's content (quotes and backslashes escaped). */
function cssString(text: string): string {
  return `"${text.replace(/[\\"]/g, (c) => `\\${c}`).replace(/[\n\r]/g, ' ')}"`;
}

/**
 * CSS that marks in the mode machine picture (`semo graph modes`: a
 * `g.team[data-team]` per team, a `g.mode[data-mode]` per mode) the mode
 * each running robot is in.
 */
export function modeHighlightCss(view: MonitorView): string {
  const rules = new Set<string>();
  for (const robot of active(view)) {
    if (robot.mode) {
      rules.add(
        `g.team[data-team=${cssString(robot.team)}] g[data-mode=${cssString(robot.mode)}] rect ` +
          '{ stroke: #d62728; stroke-width: 3px; }',
      );
    }
  }
  return [...rules].join('\n');
}

/** One line per robot for the picture's caption: robot, team, state, mode, services. */
export function modeCaption(view: MonitorView): string[] {
  return view.robots.map((r) => {
    const state = r.lost ? 'LOST' : r.state;
    const services = r.services.map((s) => `${s.plan}=${s.service}`).join(', ');
    return [
      `${r.robot}${r.isLeader ? ' ★' : ''} (${r.team})`,
      state,
      r.mode ?? '',
      services ? `[${services}]` : '',
    ]
      .filter((p) => p !== '')
      .join(' · ');
  });
}
