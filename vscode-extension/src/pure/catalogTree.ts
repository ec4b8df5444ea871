// The Robots panel's tree, built from the server's `semo/catalog` answer:
// robot types → "services" (with parameters) and "values" (with types), and
// the operator console (`USER`) last, shown as what it is: no robot type.
// Pure data (no VS Code types) so that it is tested on its own; the view
// turns each node into a TreeItem.

/** `semo/catalog`'s result (server/src/handlers/catalog.rs). */
export interface CatalogResult {
  robots: CatalogRobot[];
  /** The operator pseudo-robot (`USER`), when the catalog has one. */
  user?: CatalogRobot | null;
}

export interface CatalogRobot {
  name: string;
  aliases?: string[];
  doc?: string | null;
  capabilities?: string[];
  services: CatalogService[];
  values: CatalogValue[];
}

export interface CatalogService {
  name: string;
  signature?: string;
  params: { name: string; type: string; optional?: boolean }[];
  doc?: string | null;
}

export interface CatalogValue {
  name: string;
  type: string;
  unit?: string | null;
  doc?: string | null;
}

/** What clicking a node writes at the cursor. */
export type Insertion = { snippet: string } | { text: string };

export interface TreeNode {
  /** Unique within the tree (robot/section/name), stable across refreshes. */
  id: string;
  kind: 'robot' | 'operator' | 'section' | 'service' | 'value';
  label: string;
  /** Shown greyed beside the label. */
  description?: string;
  /** Markdown for the hover. */
  tooltip?: string;
  insert?: Insertion;
  children: TreeNode[];
}

/** Escapes text for the snippet syntax (as `ide::mission::snippets::escape`). */
export function escapeSnippet(text: string): string {
  return text.replace(/[\\$}]/g, (c) => `\\${c}`);
}

/**
 * The call a service's entry inserts, by the rule the server's completion
 * uses (`service_call_snippet` in compiler/src/ide/mission/completion.rs): required
 * parameters become placeholders, optional ones are left out.
 */
export function serviceCallSnippet(service: CatalogService): string {
  const name = escapeSnippet(service.name);
  const required = service.params
    .filter((p) => !p.optional)
    .map((p, i) => `\${${i + 1}:${escapeSnippet(p.name)}}`);
  if (service.params.length === 0) {
    return `${name}()`;
  }
  if (required.length === 0) {
    return `${name}($1)$0`;
  }
  return `${name}(${required.join(', ')})$0`;
}

/** `(distance: number, speed?: number)`: the parameters as the panel shows them. */
export function parameterList(service: CatalogService): string {
  const params = service.params.map((p) => `${p.name}${p.optional ? '?' : ''}: ${p.type}`);
  return `(${params.join(', ')})`;
}

function valueType(value: CatalogValue): string {
  return value.unit ? `${value.type} (${value.unit})` : value.type;
}

function robotTooltip(robot: CatalogRobot): string {
  const lines = [`**${robot.name}**`];
  if (robot.aliases && robot.aliases.length > 0) {
    lines.push(`also: ${robot.aliases.join(', ')}`);
  }
  if (robot.doc) {
    lines.push('', robot.doc);
  }
  if (robot.capabilities && robot.capabilities.length > 0) {
    lines.push('', `capabilities: ${robot.capabilities.join(', ')}`);
  }
  return lines.join('\n');
}

function robotNode(robot: CatalogRobot): TreeNode {
  const services: TreeNode[] = [...robot.services]
    .sort((a, b) => a.name.localeCompare(b.name))
    .map((s) => ({
      id: `${robot.name}/services/${s.name}`,
      kind: 'service',
      label: s.name,
      description: parameterList(s),
      tooltip: [`\`${s.signature ?? s.name + parameterList(s)}\``, s.doc ?? '']
        .filter((l) => l !== '')
        .join('\n\n'),
      insert: { snippet: serviceCallSnippet(s) },
      children: [],
    }));
  const values: TreeNode[] = [...robot.values]
    .sort((a, b) => a.name.localeCompare(b.name))
    .map((v) => ({
      id: `${robot.name}/values/${v.name}`,
      kind: 'value',
      label: v.name,
      description: valueType(v),
      tooltip: [`\`${v.name}: ${valueType(v)}\``, v.doc ?? ''].filter((l) => l !== '').join('\n\n'),
      insert: { text: v.name },
      children: [],
    }));
  const sections: TreeNode[] = [];
  if (services.length > 0) {
    sections.push({
      id: `${robot.name}/services`,
      kind: 'section',
      label: 'services',
      description: String(services.length),
      children: services,
    });
  }
  if (values.length > 0) {
    sections.push({
      id: `${robot.name}/values`,
      kind: 'section',
      label: 'values',
      description: String(values.length),
      children: values,
    });
  }
  return {
    id: robot.name,
    kind: 'robot',
    label: robot.name,
    description: robot.aliases && robot.aliases.length > 0 ? robot.aliases.join(', ') : undefined,
    tooltip: robotTooltip(robot),
    children: sections,
  };
}

/** The operator console: its values are what missions receive from it. */
function operatorNode(user: CatalogRobot): TreeNode {
  return {
    ...robotNode(user),
    kind: 'operator',
    description: 'operator console, not a robot type',
    tooltip: [
      `**${user.name}**: the operator console, not a robot type`,
      'Missions receive its values from it (`USER.RC_CMD`); no robot is of this type.',
      user.doc ?? '',
    ]
      .filter((l) => l !== '')
      .join('\n\n'),
  };
}

/**
 * The tree: robot types by name, the operator console last. Tolerates
 * a malformed answer (anything not shaped like a catalog gives no nodes),
 * since a panel must never throw.
 */
export function buildTree(result: unknown): TreeNode[] {
  if (!result || typeof result !== 'object') {
    return [];
  }
  const catalog = result as Partial<CatalogResult>;
  const robots = Array.isArray(catalog.robots) ? catalog.robots.filter(isRobot) : [];
  const nodes = [...robots].sort((a, b) => a.name.localeCompare(b.name)).map(robotNode);
  if (catalog.user && isRobot(catalog.user) && !robots.some((r) => r.name === catalog.user!.name)) {
    nodes.push(operatorNode(catalog.user));
  }
  return nodes;
}

function isRobot(r: unknown): r is CatalogRobot {
  if (!r || typeof r !== 'object') {
    return false;
  }
  const robot = r as CatalogRobot;
  return (
    typeof robot.name === 'string' &&
    Array.isArray(robot.services) &&
    Array.isArray(robot.values) &&
    robot.services.every((s) => s && typeof s.name === 'string' && Array.isArray(s.params)) &&
    robot.values.every((v) => v && typeof v.name === 'string')
  );
}
