// The "Robots (live)" view: the robots of a running mission, fed by the
// server's `semo/monitor` notifications (docs/live-monitor.md). "SeMo:
// Monitor Robots" starts the server's monitor on the active mission (the
// broker from `semo.monitor.broker`, else the mission's deployment file);
// "SeMo: Stop Monitoring" ends it.

import * as vscode from 'vscode';
import { buildLiveTree, isMonitorView, LiveNode, MonitorView } from './pure/liveRobots';
import { Server } from './server';

export class LiveRobotsView implements vscode.TreeDataProvider<LiveNode>, vscode.Disposable {
  private view: MonitorView | undefined;
  /** The mission being monitored (its URI), if any. */
  private monitored: string | undefined;
  private readonly changed = new vscode.EventEmitter<LiveNode | undefined>();
  readonly onDidChangeTreeData = this.changed.event;
  private readonly disposables: vscode.Disposable[] = [];
  private listener: vscode.Disposable | undefined;

  constructor(private readonly server: Server) {
    this.disposables.push(
      this.changed,
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

  /** SeMo: Stop Monitoring. */
  async stop(): Promise<void> {
    const uri = this.monitored;
    this.monitored = undefined;
    this.view = undefined;
    this.changed.fire(undefined);
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
