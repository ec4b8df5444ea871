// The Robots panel (the thesis editor's left panel): robot types the active
// document sees → services and values, from `semo/catalog`. Clicking an
// entry writes it at the cursor.

import * as vscode from 'vscode';
import { buildTree, TreeNode } from './pure/catalogTree';
import { Server } from './server';

const CATALOG_FILES = '**/*.robot.xml';

export class RobotsView implements vscode.TreeDataProvider<TreeNode>, vscode.Disposable {
  private roots: TreeNode[] = [];
  private readonly changed = new vscode.EventEmitter<TreeNode | undefined>();
  readonly onDidChangeTreeData = this.changed.event;
  private readonly disposables: vscode.Disposable[] = [];
  private timer: NodeJS.Timeout | undefined;
  /** The document whose catalog is shown: the last SeMo editor. */
  private documentUri: vscode.Uri | undefined;

  constructor(private readonly server: Server) {
    const watcher = vscode.workspace.createFileSystemWatcher(CATALOG_FILES);
    const later = () => this.refreshSoon();
    this.disposables.push(
      watcher,
      watcher.onDidChange(later),
      watcher.onDidCreate(later),
      watcher.onDidDelete(later),
      vscode.workspace.onDidChangeTextDocument((e) => {
        if (e.document.fileName.endsWith('.robot.xml')) {
          this.refreshSoon();
        }
      }),
      vscode.window.onDidChangeActiveTextEditor(() => this.refreshSoon()),
      // The server reads the workspace's catalog files after it started and
      // publishes their diagnostics then: the catalog may have grown.
      vscode.languages.onDidChangeDiagnostics((e) => {
        if (e.uris.some((u) => u.path.endsWith('.robot.xml') || u.path.endsWith('.mission'))) {
          this.refreshSoon();
        }
      }),
      server.onReady(() => this.refreshSoon()),
      this.changed,
    );
  }

  /** Coalesces bursts (typing in a catalog, switching editors) into one request. */
  refreshSoon(): void {
    if (this.timer) {
      clearTimeout(this.timer);
    }
    this.timer = setTimeout(() => void this.refresh(), 300);
  }

  async refresh(): Promise<void> {
    const editor = vscode.window.activeTextEditor;
    if (editor && editor.document.languageId === 'semo') {
      this.documentUri = editor.document.uri;
    }
    const client = this.server.client;
    if (!client || !client.isRunning()) {
      return;
    }
    try {
      const params = this.documentUri ? { uri: this.documentUri.toString() } : {};
      const result = await client.sendRequest('semo/catalog', params);
      this.roots = buildTree(result);
    } catch (e) {
      this.server.output.appendLine(`[warn] semo/catalog failed: ${e}`);
      return;
    }
    this.changed.fire(undefined);
  }

  /** Refreshes whenever the panel is shown: what it shows is then current. */
  attach(view: vscode.TreeView<TreeNode>): void {
    this.disposables.push(
      view.onDidChangeVisibility((e) => {
        if (e.visible) {
          this.refreshSoon();
        }
      }),
    );
  }

  getChildren(node?: TreeNode): TreeNode[] {
    return node ? node.children : this.roots;
  }

  getTreeItem(node: TreeNode): vscode.TreeItem {
    const collapsed =
      node.children.length === 0
        ? vscode.TreeItemCollapsibleState.None
        : node.kind === 'robot' || node.kind === 'operator'
          ? vscode.TreeItemCollapsibleState.Collapsed
          : vscode.TreeItemCollapsibleState.Expanded;
    const item = new vscode.TreeItem(node.label, collapsed);
    item.id = node.id;
    item.description = node.description;
    if (node.tooltip) {
      item.tooltip = new vscode.MarkdownString(node.tooltip);
    }
    item.iconPath = new vscode.ThemeIcon(
      {
        robot: 'hubot',
        operator: 'account',
        section: 'folder',
        service: 'symbol-method',
        value: 'symbol-field',
      }[node.kind],
    );
    item.contextValue = node.kind;
    if (node.insert) {
      item.command = {
        command: 'semo.robots.insert',
        title: 'Insert at Cursor',
        arguments: [node],
      };
    }
    return item;
  }

  dispose(): void {
    if (this.timer) {
      clearTimeout(this.timer);
    }
    this.disposables.forEach((d) => d.dispose());
  }
}

/** Writes a node's text (a call snippet or a value's name) at the cursor. */
export async function insertNode(node: TreeNode | undefined): Promise<void> {
  if (!node || !node.insert) {
    return;
  }
  const editor =
    vscode.window.activeTextEditor ??
    vscode.window.visibleTextEditors.find((e) => e.document.languageId === 'semo');
  if (!editor) {
    void vscode.window.showInformationMessage('Open a mission to insert robot services and values.');
    return;
  }
  const insert = node.insert;
  if ('snippet' in insert) {
    await editor.insertSnippet(new vscode.SnippetString(insert.snippet));
  } else {
    await editor.edit((edit) => {
      for (const selection of editor.selections) {
        edit.replace(selection, insert.text);
      }
    });
  }
  await vscode.window.showTextDocument(editor.document, editor.viewColumn);
}
