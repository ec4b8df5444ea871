import { strict as assert } from 'node:assert';
import { test } from 'node:test';
import {
  buildLiveTree,
  isMonitorView,
  liveMarks,
  modeCaption,
  modeHighlightCss,
  MonitorView,
} from '../../src/pure/liveRobots';

/** A `semo/monitor` notification shaped as server/src/monitor/roster.rs writes it. */
const VIEW: MonitorView = {
  uri: 'file:///w/patrol_groups.mission',
  mission: 'patrol_groups',
  broker: 'mqtt://127.0.0.1:1883',
  connection: 'connected',
  error: null,
  robots: [
    {
      robot: 'tb_0',
      team: 'Guards',
      state: 'running',
      lost: false,
      mode: 'PATROL',
      services: [
        { plan: 'Action', service: 'Patrol' },
        { plan: 'Report', service: 'ToBase' },
      ],
      leader: 'tb_0',
      isLeader: true,
      battery: null,
    },
    {
      robot: 'tb_1',
      team: 'Guards',
      state: 'lost',
      lost: true,
      lostBecause: 'silent',
      mode: 'PATROL',
      services: [],
      leader: 'tb_0',
      isLeader: false,
      battery: 40,
    },
    {
      robot: 'ev_0',
      team: 'Guards',
      state: 'waiting',
      lost: false,
      mode: null,
      services: [],
      leader: null,
      isLeader: false,
      battery: null,
    },
  ],
};

test('one node per robot after the connection, services below each', () => {
  const tree = buildLiveTree(VIEW);
  assert.deepEqual(
    tree.map((n) => [n.kind, n.label]),
    [
      ['connection', 'patrol_groups'],
      ['robot', 'tb_0'],
      ['robot', 'tb_1'],
      ['robot', 'ev_0'],
    ],
  );
  assert.equal(tree[0].description, 'connected · mqtt://127.0.0.1:1883');
  assert.deepEqual(
    tree[1].children.map((c) => [c.label, c.description]),
    [
      ['Action', 'Patrol'],
      ['Report', 'ToBase'],
    ],
  );
  // Ids are stable and unique, so VS Code keeps what the user expanded;
  // a robot's changes once its services come (shown expanded then).
  const ids = tree.flatMap((n) => [n.id, ...n.children.map((c) => c.id)]);
  assert.equal(new Set(ids).size, ids.length);
  assert.equal(buildLiveTree(VIEW)[1].id, tree[1].id);
  assert.notEqual(tree[1].id, buildLiveTree({ ...VIEW, robots: [{ ...VIEW.robots[0], services: [] }] })[1].id);
});

test("a robot's counted groups are in its description and tooltip", () => {
  const rooms = buildLiveTree({
    ...VIEW,
    robots: [
      {
        ...VIEW.robots[0],
        mode: 'ROOMS',
        isLeader: false,
        leader: null,
        groups: [
          { group: 'Room1', alive: 5 },
          { group: 'others', alive: 3 },
        ],
      },
      { ...VIEW.robots[0], robot: 'tb_9', groups: [] },
    ],
  });
  assert.equal(rooms[1].description, 'running · ROOMS · Room1, others');
  assert.match(rooms[1].tooltip, /groups: Room1 \(5 alive\), others \(3 alive\)/);
  // None (or a server that sends none): nothing said.
  assert.equal(rooms[2].description, 'running · PATROL · ★ leader');
  assert.doesNotMatch(rooms[2].tooltip, /groups/);
  assert.doesNotMatch(buildLiveTree(VIEW)[1].tooltip, /groups/);
});

test('the leader is marked, lost robots are marked with the reason, waiting ones too', () => {
  const [, leader, lost, waiting] = buildLiveTree(VIEW);
  assert.equal(leader.description, 'running · PATROL · ★ leader');
  assert.equal(leader.icon, 'star-full');
  assert.equal(lost.description, 'LOST · PATROL · battery 40');
  assert.equal(lost.icon, 'error');
  assert.match(lost.tooltip, /no heartbeat for three periods/);
  assert.equal(waiting.description, 'waiting');
  assert.equal(waiting.icon, 'watch');
  const will = buildLiveTree({
    ...VIEW,
    robots: [{ ...VIEW.robots[1], lostBecause: 'lastWill' }],
  })[1];
  assert.match(will.tooltip, /last will/);
});

test('a broker that cannot be reached shows why', () => {
  const [connection] = buildLiveTree({
    ...VIEW,
    connection: 'disconnected',
    error: 'I/O: Connection refused (os error 111)',
  });
  assert.equal(connection.icon, 'debug-disconnect');
  assert.match(connection.tooltip, /Connection refused/);
});

test('only monitor views are taken', () => {
  assert.ok(isMonitorView(VIEW));
  assert.ok(!isMonitorView({ uri: 'x' }));
  assert.ok(!isMonitorView(null));
});

/** Two running robots of one team in one mode, one lost, one waiting: with the mission lines. */
const LINED: MonitorView = {
  ...VIEW,
  robots: [
    { ...VIEW.robots[0], modeLine: 30, services: [{ plan: 'Action', service: 'Patrol', line: 12 }] },
    {
      ...VIEW.robots[0],
      robot: 'tb_2',
      isLeader: false,
      modeLine: 30,
      services: [{ plan: 'Action', service: 'Patrol', line: 12 }],
    },
    { ...VIEW.robots[1], modeLine: 30 },
    { ...VIEW.robots[0], robot: 'tb_3', state: 'waiting', mode: null, modeLine: null, services: [] },
  ],
};

test('the mission lines say which running robots are in a mode or run a service', () => {
  assert.deepEqual(liveMarks(LINED), [
    { line: 12, kind: 'service', text: '▶ running: tb_0, tb_2' },
    { line: 30, kind: 'mode', text: '◀ in this mode: tb_0, tb_2' },
  ]);
  // A view from an older server (no lines) marks nothing.
  assert.deepEqual(liveMarks(VIEW), []);
});

test('the mode machine marks the modes running robots are in, by team', () => {
  const css = modeHighlightCss(LINED);
  assert.equal(css.split('\n').length, 1);
  assert.match(css, /^g\.team\[data-team="Guards"\] g\[data-mode="PATROL"\] rect \{/);
  // Names are CSS strings: a quote cannot end the selector.
  const odd = modeHighlightCss({
    ...LINED,
    robots: [{ ...VIEW.robots[0], team: 'A"] * {x', mode: 'M' }],
  });
  assert.ok(odd.includes('data-team="A\\"] * {x"'), odd);
  assert.deepEqual(modeCaption(LINED).slice(0, 2), [
    'tb_0 ★ (Guards) · running · PATROL · [Action=Patrol]',
    'tb_2 (Guards) · running · PATROL · [Action=Patrol]',
  ]);
});
