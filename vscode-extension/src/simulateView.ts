// "SeMo: Simulate Mission": picks a `*.scenario.json` beside the mission,
// asks the server to run it (`workspace/executeCommand` `semo.simulate`, the
// same run as `semo simulate`) and shows the summary and the timeline in a
// webview. Clicking a mode band or a service bar opens the mission line
// that caused it. The failed expectations appear as diagnostics on the
// scenario file (the server publishes them).

import * as crypto from 'crypto';
import * as fs from 'fs';
import * as path from 'path';
import * as vscode from 'vscode';
import { ExecuteCommandRequest } from 'vscode-languageclient/node';
import { missionLine, scenarioCandidates, simulationPage } from './pure/simulation';
import { Server } from './server';

/** The server's `workspace/executeCommand` name for a simulation. */
export const SIMULATE = 'semo.simulate';

interface SimulateResult {
  ok: boolean;
  summary: string;
  svg: string;
}

function activeMission(): vscode.TextDocument | undefined {
  const active = vscode.window.activeTextEditor?.document;
  if (active?.languageId === 'semo') {
    return active;
  }
  return vscode.window.visibleTextEditors.find((e) => e.document.languageId === 'semo')?.document;
}

/** The scenario to run: the only one beside the mission, or the one picked. */
async function pickScenario(mission: vscode.TextDocument): Promise<vscode.Uri | undefined> {
  const folder = path.dirname(mission.uri.fsPath);
  let names: string[] = [];
  try {
    names = fs.readdirSync(folder);
  } catch {
    // An unreadable folder offers no scenario: said below.
  }
  const candidates = scenarioCandidates(path.basename(mission.uri.fsPath), names);
  if (candidates.length === 0) {
    void vscode.window.showWarningMessage(
      `No scenario (*.scenario.json) beside ${path.basename(mission.uri.fsPath)}.`,
    );
    return undefined;
  }
  const name =
    candidates.length === 1
      ? candidates[0]
      : await vscode.window.showQuickPick(candidates, { placeHolder: 'Scenario to simulate' });
  return name ? vscode.Uri.file(path.join(folder, name)) : undefined;
}

export class SimulationViews implements vscode.Disposable {
  private readonly panels = new Map<string, vscode.WebviewPanel>();

  constructor(private readonly server: Server) {}

  async simulate(): Promise<void> {
    const mission = activeMission();
    if (!mission || mission.uri.scheme !== 'file') {
      void vscode.window.showWarningMessage('Open a saved mission (.mission) to simulate it.');
      return;
    }
    const client = this.server.running();
    if (!client) {
      return;
    }
    const scenario = await pickScenario(mission);
    if (!scenario) {
      return;
    }
    const title = `Simulation: ${path.basename(scenario.fsPath)}`;
    let body: { summary: string; svg: string };
    try {
      const result: SimulateResult = await client.sendRequest(ExecuteCommandRequest.type, {
        command: SIMULATE,
        arguments: [{ uri: mission.uri.toString(), scenario: scenario.toString() }],
      });
      body = result;
      if (!result.ok) {
        void vscode.window.showWarningMessage(
          'SeMo: an expectation of the scenario failed (see the scenario file).',
        );
      }
    } catch (e) {
      const message = e instanceof Error ? e.message : String(e);
      void vscode.window.showErrorMessage(`SeMo: ${message}`);
      return;
    }
    const panel = this.panel(mission.uri, title);
    const nonce = crypto.randomBytes(16).toString('base64');
    panel.webview.html = simulationPage(title, body.summary, body.svg, nonce);
  }

  /** The mission's simulation panel, made once; its clicks open mission lines. */
  private panel(mission: vscode.Uri, title: string): vscode.WebviewPanel {
    const key = mission.toString();
    const existing = this.panels.get(key);
    if (existing) {
      existing.title = title;
      existing.reveal(vscode.ViewColumn.Beside, true);
      return existing;
    }
    const panel = vscode.window.createWebviewPanel(
      'semo.simulation',
      title,
      { viewColumn: vscode.ViewColumn.Beside, preserveFocus: true },
      { enableScripts: true, retainContextWhenHidden: false },
    );
    this.panels.set(key, panel);
    panel.onDidDispose(() => this.panels.delete(key));
    panel.webview.onDidReceiveMessage(async (message: { line?: string }) => {
      const line = missionLine(message?.line);
      if (line === undefined) {
        return;
      }
      const document = await vscode.workspace.openTextDocument(mission);
      const position = new vscode.Position(line, 0);
      await vscode.window.showTextDocument(document, {
        viewColumn: vscode.ViewColumn.One,
        selection: new vscode.Range(position, position),
      });
    });
    return panel;
  }

  dispose(): void {
    this.panels.forEach((p) => p.dispose());
  }
}
