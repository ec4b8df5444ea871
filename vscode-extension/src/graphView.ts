// "SeMo: Show Task Graph" and "SeMo: Show Mode Machine": a webview with the
// SVG the server draws (`semo/graphSvg`, the same picture as `semo graph svg`
// and `semo graph modes`). The picture follows the document as it changes.

import * as path from 'path';
import * as vscode from 'vscode';
import { Server } from './server';

interface GraphSvgResult {
  svg: string;
}

type Kind = 'taskgraph' | 'modes';

const TITLES: Record<Kind, string> = { taskgraph: 'Task Graph', modes: 'Mode Machine' };

function documentFor(kind: Kind): vscode.TextDocument | undefined {
  const fits = (d: vscode.TextDocument) =>
    kind === 'taskgraph' ? d.fileName.endsWith('.taskgraph.xml') : d.languageId === 'semo';
  const active = vscode.window.activeTextEditor?.document;
  if (active && fits(active)) {
    return active;
  }
  return vscode.window.visibleTextEditors.map((e) => e.document).find(fits);
}

function escapeHtml(text: string): string {
  return text.replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]!);
}

/**
 * The page: the SVG inline, no scripts (the content security policy allows
 * none), on a light background since the drawing uses dark strokes.
 */
export function page(title: string, body: string): string {
  return `<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'; img-src data:;">
<title>${escapeHtml(title)}</title>
<style>
  body { background: #fff; color: #222; margin: 0; padding: 12px; font-family: sans-serif; }
  .error { color: #a00; white-space: pre-wrap; }
  svg { max-width: none; }
</style></head>
<body>${body}</body></html>`;
}

export class GraphViews implements vscode.Disposable {
  private readonly panels = new Map<string, vscode.WebviewPanel>();
  private readonly disposables: vscode.Disposable[] = [];
  private timers = new Map<string, NodeJS.Timeout>();

  constructor(private readonly server: Server) {
    this.disposables.push(
      vscode.workspace.onDidChangeTextDocument((e) => this.redrawSoon(e.document)),
    );
  }

  async show(kind: Kind): Promise<void> {
    const document = documentFor(kind);
    if (!document) {
      const what = kind === 'taskgraph' ? 'a task graph (.taskgraph.xml)' : 'a mission (.mission)';
      void vscode.window.showWarningMessage(`Open ${what} first.`);
      return;
    }
    const key = `${kind}:${document.uri.toString()}`;
    let panel = this.panels.get(key);
    if (!panel) {
      panel = vscode.window.createWebviewPanel(
        'semo.graph',
        `${TITLES[kind]}: ${path.basename(document.uri.path)}`,
        { viewColumn: vscode.ViewColumn.Beside, preserveFocus: true },
        { enableScripts: false, retainContextWhenHidden: false },
      );
      this.panels.set(key, panel);
      panel.onDidDispose(() => this.panels.delete(key));
    } else {
      panel.reveal(vscode.ViewColumn.Beside, true);
    }
    await this.draw(kind, document, panel);
  }

  private redrawSoon(document: vscode.TextDocument): void {
    for (const kind of ['taskgraph', 'modes'] as Kind[]) {
      const key = `${kind}:${document.uri.toString()}`;
      const panel = this.panels.get(key);
      if (!panel) {
        continue;
      }
      clearTimeout(this.timers.get(key));
      this.timers.set(key, setTimeout(() => void this.draw(kind, document, panel), 500));
    }
  }

  private async draw(kind: Kind, document: vscode.TextDocument, panel: vscode.WebviewPanel) {
    const title = `${TITLES[kind]}: ${path.basename(document.uri.path)}`;
    const client = this.server.client;
    if (!client || !client.isRunning()) {
      panel.webview.html = page(title, '<p class="error">The SeMo server is not running.</p>');
      return;
    }
    try {
      const result = await client.sendRequest<GraphSvgResult>('semo/graphSvg', {
        textDocument: { uri: document.uri.toString() },
      });
      panel.webview.html = page(title, result.svg);
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
