// The "Robots (live)" view: the robots of a running mission, fed by the
// server's `semo/monitor` notifications (docs/live-monitor.md). "SeMo:
// Monitor Robots" starts the server's monitor on the active mission (the
// broker from `semo.monitor.broker`, else the mission's deployment file);
// "SeMo: Stop Monitoring" ends it.

import * as vscode from 'vscode';
import { buildLiveTree, isMonitorView, liveMarks, LiveNode, MonitorView } from './pure/liveRobots';
import { Server } from './server';

export class LiveRobotsView implements vscode.TreeDataProvider<LiveNode>, vscode.Disposable {
  private view: MonitorView | undefined;
  /** The mission being monitored (its URI), if any. */
  private monitored: string | undefined;
  private readonly changed = new vscode.EventEmitter<LiveNode | undefined>();
  readonly onDidChangeTreeData = this.changed.event;
  private readonly disposables: vscode.Disposable[] = [];
  private listener: vscode.Disposable | undefined;
  private readonly viewed = new vscode.EventEmitter<MonitorView | undefined>();
  /** Every view of the monitored mission as it comes (undefined: monitoring ended). */
  readonly onView = this.viewed.event;
  /** The mission's lines where robots are: their mode's, their services'. */
  private readonly modeMark = vscode.window.createTextEditorDecorationType({
    isWholeLine: true,
    backgroundColor: new vscode.ThemeColor('editor.rangeHighlightBackground'),
    after: { margin: '0 0 0 2em', color: new vscode.ThemeColor('editorCodeLens.foreground') },
  });
  private readonly serviceMark = vscode.window.createTextEditorDecorationType({
    after: { margin: '0 0 0 2em', color: new vscode.ThemeColor('editorCodeLens.foreground') },
  });

  constructor(private readonly server: Server) {
    this.disposables.push(
      this.changed,
      this.viewed,
      this.modeMark,
      this.serviceMark,
      vscode.window.onDidChangeVisibleTextEditors(() => this.mark()),
      // Closing the mission ends its monitor in the server too.
      vscode.workspace.onDidCloseTextDocument((d) => {
        if (d.uri.toString() === this.monitored) {
          void this.stop();
        }
      }),
      // A new client (started or restarted) has no handler yet and no monitor.
      server.onReady(() => {
        this.listen();
        if (this.monitored) {
          this.monitored = undefined;
          this.view = undefined;
          void vscode.commands.executeCommand('setContext', 'semo.monitoring', false);
          this.changed.fire(undefined);
        }
      }),
    );
    this.listen();
  }

  private listen(): void {
    this.listener?.dispose();
    const client = this.server.client;
    if (!client) {
      return;
    }
    this.listener = client.onNotification('semo/monitor', (params: unknown) => {
      if (isMonitorView(params) && params.uri === this.monitored) {
        this.view = params;
        this.changed.fire(undefined);
        this.viewed.fire(params);
        this.mark();
      }
    });
  }

  /** SeMo: Monitor Robots, on the active mission. */
  async start(): Promise<void> {
    const editor = vscode.window.activeTextEditor;
    const document =
      editor?.document.languageId === 'semo'
        ? editor.document
        : vscode.window.visibleTextEditors.find((e) => e.document.languageId === 'semo')?.document;
    if (!document) {
      void vscode.window.showInformationMessage('Open the mission whose robots to monitor.');
      return;
    }
    const client = this.server.client;
    if (!client || !client.isRunning()) {
      void vscode.window.showErrorMessage('SeMo: the language server is not running.');
      return;
    }
    const broker = vscode.workspace
      .getConfiguration('semo', document.uri)
      .get<string>('monitor.broker', '')
      .trim();
    const uri = document.uri.toString();
    if (this.monitored && this.monitored !== uri) {
      await this.stop();
    }
    this.monitored = uri;
    this.view = undefined;
    this.changed.fire(undefined);
    try {
      const answer = (await client.sendRequest('semo/monitor/start', {
        uri,
        broker: broker || undefined,
      })) as { mission: string; broker: string };
      this.server.output.appendLine(`[info] monitoring ${answer.mission} on ${answer.broker}`);
      await vscode.commands.executeCommand('setContext', 'semo.monitoring', true);
      await vscode.commands.executeCommand('semo.live.focus');
    } catch (e) {
      this.monitored = undefined;
      const message = e instanceof Error ? e.message : String(e);
      void vscode.window.showErrorMessage(`SeMo: ${message}`);
    }
  }

  /** The latest view of the monitored mission, if any. */
  latest(): MonitorView | undefined {
    return this.view;
  }

  /**
   * Marks, in every editor of the monitored mission, the line of each
   * running robot's mode and of each service it runs (cleared elsewhere).
   */
  private mark(): void {
    const marks = this.view ? liveMarks(this.view) : [];
    for (const editor of vscode.window.visibleTextEditors) {
      const ours = editor.document.uri.toString() === this.monitored;
      const of = (kind: 'mode' | 'service') =>
        (ours ? marks : [])
          .filter((m) => m.kind === kind && m.line <= editor.document.lineCount)
          .map((m) => ({
            range: editor.document.lineAt(m.line - 1).range,
            renderOptions: { after: { contentText: m.text } },
          }));
      editor.setDecorations(this.modeMark, of('mode'));
      editor.setDecorations(this.serviceMark, of('service'));
    }
  }

  /** SeMo: Stop Monitoring. */
  async stop(): Promise<void> {
    const uri = this.monitored;
    this.monitored = undefined;
    this.view = undefined;
    this.changed.fire(undefined);
    this.viewed.fire(undefined);
    this.mark();
    await vscode.commands.executeCommand('setContext', 'semo.monitoring', false);
    const client = this.server.client;
    if (uri && client && client.isRunning()) {
      try {
        await client.sendRequest('semo/monitor/stop', { uri });
      } catch (e) {
        this.server.output.appendLine(`[warn] semo/monitor/stop failed: ${e}`);
      }
    }
  }

  getChildren(node?: LiveNode): LiveNode[] {
    if (node) {
      return node.children;
    }
    return this.view ? buildLiveTree(this.view) : [];
  }

  getTreeItem(node: LiveNode): vscode.TreeItem {
    const item = new vscode.TreeItem(
      node.label,
      node.children.length > 0
        ? vscode.TreeItemCollapsibleState.Expanded
        : vscode.TreeItemCollapsibleState.None,
    );
    item.id = node.id;
    item.description = node.description;
    item.tooltip = new vscode.MarkdownString(node.tooltip);
    item.iconPath = new vscode.ThemeIcon(
      node.icon,
      node.color ? new vscode.ThemeColor(node.color) : undefined,
    );
    item.contextValue = node.kind;
    return item;
  }

  dispose(): void {
    this.listener?.dispose();
    this.disposables.forEach((d) => d.dispose());
  }
}
