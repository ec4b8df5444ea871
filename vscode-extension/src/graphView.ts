// "SeMo: Show Task Graph" and "SeMo: Show Mode Machine": a webview with the
// SVG the server draws (`semo/graphSvg`, the same picture as `semo graph svg`
// and `semo graph modes`). The picture follows the document as it changes.
// Show Task Graph takes a task graph file (`*.taskgraph.xml`, or a generated
// robot's `taskgraph.xml`) or a mission: then a robot's refined task graph,
// the robot picked from the mission's robots.

import * as path from 'path';
import * as vscode from 'vscode';
import { MonitorView, modeCaption, modeHighlightCss } from './pure/liveRobots';
import { Server } from './server';

interface GraphSvgResult {
  svg: string;
  /** For a mission's robot: the robot drawn and every robot of the mission. */
  robot?: string;
  robots?: string[];
}

type Kind = 'taskgraph' | 'modes';

const TITLES: Record<Kind, string> = { taskgraph: 'Task Graph', modes: 'Mode Machine' };

function documentFor(kind: Kind): vscode.TextDocument | undefined {
  const fits = (d: vscode.TextDocument) =>
    d.languageId === 'semo' || (kind === 'taskgraph' && isTaskGraphFile(d.fileName));
  const active = vscode.window.activeTextEditor?.document;
  if (active && fits(active)) {
    return active;
  }
  return vscode.window.visibleTextEditors.map((e) => e.document).find(fits);
}

/** `*.taskgraph.xml`, or `taskgraph.xml` as `semo build` names a robot's. */
export function isTaskGraphFile(fileName: string): boolean {
  return path.basename(fileName) === 'taskgraph.xml' || fileName.endsWith('.taskgraph.xml');
}

function escapeHtml(text: string): string {
  return text.replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]!);
}

/**
 * The page: the SVG inline, no scripts (the content security policy allows
 * none), on a light background since the drawing uses dark strokes.
 */
export function page(title: string, body: string, live?: MonitorView): string {
  // A running mission's robots (the live monitor): their modes marked in
  // the picture, and a line per robot above it.
  const liveCss = live ? modeHighlightCss(live) : '';
  const caption = live
    ? `<ul class="live">${modeCaption(live)
        .map((line) => `<li>${escapeHtml(line)}</li>`)
        .join('')}</ul>`
    : '';
  return `<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'; img-src data:;">
<title>${escapeHtml(title)}</title>
<style>
  body { background: #fff; color: #222; margin: 0; padding: 12px; font-family: sans-serif; }
  .error { color: #a00; white-space: pre-wrap; }
  .live { margin: 0 0 8px 0; padding-left: 16px; font-size: 12px; color: #d62728; }
  svg { max-width: none; }
${liveCss}
</style></head>
<body>${caption}${body}</body></html>`;
}

function titleOf(kind: Kind, document: vscode.TextDocument, robot?: string): string {
  const name = path.basename(document.uri.path);
  return robot ? `${TITLES[kind]}: ${robot} (${name})` : `${TITLES[kind]}: ${name}`;
}

export class GraphViews implements vscode.Disposable {
  private readonly panels = new Map<string, vscode.WebviewPanel>();
  private readonly disposables: vscode.Disposable[] = [];
  private timers = new Map<string, NodeJS.Timeout>();
  /** The last picture of each panel, redrawn at once as the robots move. */
  private readonly drawn = new Map<string, { title: string; svg: string }>();
  /** The live monitor's latest view (its mission's mode machine shows it). */
  private live: MonitorView | undefined;

  constructor(
    private readonly server: Server,
    liveViews?: vscode.Event<MonitorView | undefined>,
  ) {
    this.disposables.push(
      vscode.workspace.onDidChangeTextDocument((e) => this.redrawSoon(e.document)),
    );
    if (liveViews) {
      this.disposables.push(liveViews((view) => this.showLive(view)));
    }
  }

  /** The robots of a monitored mission on its mode machine panel, if open. */
  private showLive(view: MonitorView | undefined): void {
    const previous = this.live?.uri;
    this.live = view;
    for (const uri of new Set([previous, view?.uri])) {
      const key = `modes:${uri}`;
      const panel = this.panels.get(key);
      const drawn = this.drawn.get(key);
      if (uri && panel && drawn) {
        panel.webview.html = page(drawn.title, drawn.svg, this.liveFor(uri));
      }
    }
  }

  private liveFor(uri: string): MonitorView | undefined {
    return this.live?.uri === uri ? this.live : undefined;
  }

  async show(kind: Kind): Promise<void> {
    const document = documentFor(kind);
    if (!document) {
      const what =
        kind === 'taskgraph' ? 'a task graph (.taskgraph.xml) or a mission' : 'a mission (.mission)';
      void vscode.window.showWarningMessage(`Open ${what} first.`);
      return;
    }
    let robot: string | undefined;
    if (kind === 'taskgraph' && document.languageId === 'semo') {
      robot = await this.pickRobot(document);
      if (robot === undefined) {
        return;
      }
    }
    const key = `${kind}:${document.uri.toString()}${robot ? `#${robot}` : ''}`;
    let panel = this.panels.get(key);
    if (!panel) {
      panel = vscode.window.createWebviewPanel(
        'semo.graph',
        titleOf(kind, document, robot),
        { viewColumn: vscode.ViewColumn.Beside, preserveFocus: true },
        { enableScripts: false, retainContextWhenHidden: false },
      );
      this.panels.set(key, panel);
      panel.onDidDispose(() => {
        this.panels.delete(key);
        this.drawn.delete(key);
      });
    } else {
      panel.reveal(vscode.ViewColumn.Beside, true);
    }
    await this.draw(kind, document, panel, robot);
  }

  /**
   * The robot of a mission whose task graph to draw: the only one, or the
   * one picked among the mission's robots; undefined when the pick is
   * dismissed or the server cannot say (then it says why).
   */
  private async pickRobot(document: vscode.TextDocument): Promise<string | undefined> {
    const client = this.server.running();
    if (!client) {
      return undefined;
    }
    try {
      const first = await client.sendRequest<GraphSvgResult>('semo/graphSvg', {
        textDocument: { uri: document.uri.toString() },
        kind: 'taskgraph',
      });
      const robots = first.robots ?? [];
      if (robots.length <= 1) {
        return first.robot;
      }
      return await vscode.window.showQuickPick(robots, {
        title: `Task graph of which robot of ${path.basename(document.uri.path)}?`,
      });
    } catch (e) {
      const message = e instanceof Error ? e.message : String(e);
      void vscode.window.showErrorMessage(`SeMo: ${message}`);
      return undefined;
    }
  }

  private redrawSoon(document: vscode.TextDocument): void {
    const prefix = (kind: Kind) => `${kind}:${document.uri.toString()}`;
    for (const [key, panel] of this.panels) {
      const kind = (['taskgraph', 'modes'] as Kind[]).find(
        (k) => key === prefix(k) || key.startsWith(`${prefix(k)}#`),
      );
      if (!kind) {
        continue;
      }
      const robot = key.includes('#') ? key.slice(key.indexOf('#') + 1) : undefined;
      clearTimeout(this.timers.get(key));
      this.timers.set(key, setTimeout(() => void this.draw(kind, document, panel, robot), 500));
    }
  }

  private async draw(
    kind: Kind,
    document: vscode.TextDocument,
    panel: vscode.WebviewPanel,
    robot?: string,
  ) {
    const title = titleOf(kind, document, robot);
    const client = this.server.client;
    if (!client || !client.isRunning()) {
      panel.webview.html = page(title, '<p class="error">The SeMo server is not running.</p>');
      return;
    }
    try {
      const uri = document.uri.toString();
      const result = await client.sendRequest<GraphSvgResult>('semo/graphSvg', {
        textDocument: { uri },
        ...(robot ? { kind: 'taskgraph', robot } : {}),
      });
      const live = kind === 'modes' ? this.liveFor(uri) : undefined;
      if (kind === 'modes') {
        this.drawn.set(`modes:${uri}`, { title, svg: result.svg });
      }
      panel.webview.html = page(title, result.svg, live);
    } catch (e) {
      const message = e instanceof Error ? e.message : String(e);
      panel.webview.html = page(title, `<p class="error">${escapeHtml(message)}</p>`);
    }
  }

  dispose(): void {
    this.timers.forEach((t) => clearTimeout(t));
    this.panels.forEach((p) => p.dispose());
    this.disposables.forEach((d) => d.dispose());
  }
}
