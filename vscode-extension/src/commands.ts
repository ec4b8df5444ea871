// The palette's SeMo commands that are not about the server's life.

import * as path from 'path';
import * as vscode from 'vscode';
import { ExecuteCommandRequest } from 'vscode-languageclient/node';
import {
  BACK_UP_AND_REGENERATE,
  ConflictRefusal,
  GenerateArguments,
  forcePrompt,
  generateWithConsent,
} from './pure/generate';
import { missionTemplateSnippet } from './pure/template';
import { VERIFY_COMMAND, VerifyAnswer, verifyMessage } from './pure/verify';
import { GENERATE_CODE_COMMAND, Server } from './server';

/** The server's `workspace/executeCommand` name for code generation. */
export const GENERATE_CODE = GENERATE_CODE_COMMAND;

/** What the server answers to `semo.generateCode` (docs: the server's `generate_code`). */
interface GenerateSummary {
  refused?: boolean;
  errors?: string[];
  robots?: unknown[];
  outputFolder?: string;
  kept?: { path: string; why: string }[];
  recovered?: string[];
  /** The build plan's findings in semo.toml (built anyway). */
  warnings?: string[];
}

/** "SeMo: New Mission from Template": an untitled mission holding the template. */
export async function newMission(): Promise<void> {
  const document = await vscode.workspace.openTextDocument({ language: 'semo', content: '' });
  const editor = await vscode.window.showTextDocument(document);
  // The same snippet as the server's completion: the cursor in the formation.
  await editor.insertSnippet(new vscode.SnippetString(missionTemplateSnippet()));
}

/** The mission a command works on: the active editor's, else the last visible one. */
function activeMission(): vscode.TextDocument | undefined {
  const active = vscode.window.activeTextEditor?.document;
  if (active?.languageId === 'semo') {
    return active;
  }
  return vscode.window.visibleTextEditors.find((e) => e.document.languageId === 'semo')?.document;
}

/**
 * The output folder setting made absolute against the mission's workspace
 * folder; undefined when it is not set, so that the server decides as
 * `semo build` does (the project file's `[build] output`, else `out` beside
 * the mission).
 */
export function outputFolderFor(document: vscode.TextDocument): string | undefined {
  const setting = vscode.workspace
    .getConfiguration('semo', document.uri)
    .get<string>('codegen.outputFolder', '')
    .trim();
  if (!setting) {
    return undefined;
  }
  if (path.isAbsolute(setting)) {
    return setting;
  }
  const folder =
    vscode.workspace.getWorkspaceFolder(document.uri)?.uri.fsPath ??
    (document.uri.scheme === 'file' ? path.dirname(document.uri.fsPath) : undefined) ??
    vscode.workspace.workspaceFolders?.[0]?.uri.fsPath;
  return folder ? path.join(folder, setting) : setting;
}

/** Whether the running server announced `command` at `initialize`. */
function serverOffers(server: Server, command: string): boolean {
  const commands =
    server.client?.initializeResult?.capabilities.executeCommandProvider?.commands ?? [];
  return commands.includes(command);
}

/**
 * "SeMo: Generate Code": asks the server (`workspace/executeCommand`
 * `semo.generateCode` with `[{ uri, outputFolder }]`) to write the mission's
 * code, with a progress notification, then shows the output folder. A code
 * lens gives its own arguments (`{ uri, team }`): that mission, that team.
 * The outcome is one notification (the server shows none: the client said
 * `generateCodeOutcome` at start-up).
 */
export async function generateCode(server: Server, lens?: unknown): Promise<void> {
  const fromLens = lens as Partial<GenerateArguments> | undefined;
  const document = fromLens?.uri
    ? await vscode.workspace.openTextDocument(vscode.Uri.parse(fromLens.uri))
    : activeMission();
  if (!document) {
    void vscode.window.showWarningMessage('Open a mission (.mission) to generate its code.');
    return;
  }
  const client = server.running();
  if (!client) {
    return;
  }
  if (!serverOffers(server, GENERATE_CODE)) {
    void vscode.window.showErrorMessage(
      `This semo server cannot generate code (it offers no "${GENERATE_CODE}" command). ` +
        'Update semo, or point semo.server.path to a newer build.',
    );
    return;
  }
  if (document.isDirty) {
    await document.save();
  }
  const outputFolder = outputFolderFor(document);
  const send = (args: GenerateArguments) =>
    vscode.window.withProgress(
      {
        location: vscode.ProgressLocation.Notification,
        title: `SeMo: generating code for ${path.basename(document.uri.path)}`,
        cancellable: false,
      },
      () =>
        client.sendRequest(ExecuteCommandRequest.type, {
          command: GENERATE_CODE,
          arguments: [args],
        }),
    );
  // Files in the way (edited, or another target's): a modal offers to save
  // them under .semo-backup/ and generate again with `force`.
  const askToForce = async (refusal: ConflictRefusal) => {
    const { message, detail } = forcePrompt(refusal);
    const choice = await vscode.window.showWarningMessage(
      message,
      { modal: true, detail },
      BACK_UP_AND_REGENERATE,
    );
    return choice === BACK_UP_AND_REGENERATE;
  };
  const result = await generateWithConsent(
    send,
    {
      uri: document.uri.toString(),
      ...(outputFolder ? { outputFolder } : {}),
      ...(fromLens?.team ? { team: fromLens.team } : {}),
    },
    askToForce,
  );
  if (result.kind === 'declined') {
    server.output.appendLine(`[info] code generation not forced:\n${result.refusal.message}`);
    return;
  }
  if (result.kind === 'failed') {
    const message = result.error instanceof Error ? result.error.message : String(result.error);
    server.output.appendLine(`[error] ${GENERATE_CODE}: ${message}`);
    void vscode.window.showErrorMessage(`SeMo: code generation failed: ${message}`, 'Show Output')
      .then((c) => c && server.output.show());
    return;
  }
  const summary = result.value as GenerateSummary | null;
  if (summary?.refused) {
    // The reasons are the mission's diagnostics: the Problems view shows them.
    const errors = summary.errors ?? [];
    server.output.appendLine(`[info] code generation refused:\n  ${errors.join('\n  ')}`);
    void vscode.window.showErrorMessage(
      `SeMo: code generation refused: ${errors.length} error(s) in ${path.basename(document.uri.path)} (see Problems)`,
    );
    void vscode.commands.executeCommand('workbench.actions.view.problems');
    return;
  }
  const written = summary?.outputFolder ?? outputFolder;
  if (!written) {
    server.output.appendLine(`[error] ${GENERATE_CODE}: the answer names no output folder`);
    return;
  }
  for (const line of summary?.recovered ?? []) {
    server.output.appendLine(`[warning] recovered: ${line}`);
  }
  for (const kept of summary?.kept ?? []) {
    server.output.appendLine(`[warning] kept ${kept.path}: ${kept.why}`);
  }
  for (const warning of summary?.warnings ?? []) {
    server.output.appendLine(`[warning] semo.toml: ${warning}`);
  }
  server.output.appendLine(`[info] generated code in ${written}`);
  const folderUri = vscode.Uri.file(written);
  try {
    await vscode.commands.executeCommand('revealInExplorer', folderUri);
  } catch {
    // Outside the workspace the explorer cannot show it; the message below can.
  }
  const open = 'Open Folder in New Window';
  const robots = summary?.robots?.length ?? 0;
  const kept = summary?.kept?.length ?? 0;
  const keptNote = kept > 0 ? ` (${kept} file(s) you edited kept: see the SeMo output)` : '';
  const choice = await vscode.window.showInformationMessage(
    `SeMo: code generated for ${robots} robot(s) in ${written}${keptNote}`,
    open,
  );
  if (choice === open) {
    await vscode.commands.executeCommand('vscode.openFolder', folderUri, { forceNewWindow: true });
  }
}

/**
 * "SeMo: Verify Mission": asks the server (`workspace/executeCommand`
 * `semo.verify` with `[{ uri }]`) to explore everything the mission's team
 * can do, as `semo verify` does, with a cancellable progress notification;
 * writes the summary to the SeMo output and sums it up in one notification.
 * The findings are also the mission's diagnostics after each save.
 */
export async function verifyMission(server: Server): Promise<void> {
  const document = activeMission();
  if (!document) {
    void vscode.window.showWarningMessage('Open a mission (.mission) to verify it.');
    return;
  }
  const client = server.running();
  if (!client) {
    return;
  }
  if (!serverOffers(server, VERIFY_COMMAND)) {
    void vscode.window.showErrorMessage(
      `This semo server cannot verify (it offers no "${VERIFY_COMMAND}" command). ` +
        'Update semo, or point semo.server.path to a newer build.',
    );
    return;
  }
  const mission = path.basename(document.uri.path);
  let answer: VerifyAnswer;
  try {
    answer = await vscode.window.withProgress(
      {
        location: vscode.ProgressLocation.Notification,
        title: `SeMo: exploring everything ${mission} can do`,
        cancellable: true,
      },
      (_progress, token) =>
        client.sendRequest(
          ExecuteCommandRequest.type,
          { command: VERIFY_COMMAND, arguments: [{ uri: document.uri.toString() }] },
          token,
        ),
    );
  } catch (error) {
    const message = error instanceof Error ? error.message : String(error);
    server.output.appendLine(`[error] ${VERIFY_COMMAND}: ${message}`);
    void vscode.window.showErrorMessage(`SeMo: verify failed: ${message}`);
    return;
  }
  server.output.appendLine(`[info] semo verify ${mission}:\n  ${answer.summary.split('\n').join('\n  ')}`);
  const { level, text } = verifyMessage(mission, answer);
  const show = level === 'info' ? vscode.window.showInformationMessage : vscode.window.showWarningMessage;
  void show(text, 'Show Output').then((c) => c && server.output.show());
}

/**
 * "SeMo: Check Workspace": the server checks every mission, catalog, strategy
 * file, task graph and project file of the workspace folders at start; this tells it that
 * each of them changed on disk (`workspace/didChangeWatchedFiles`), so it
 * reads them again and publishes their diagnostics afresh, then shows the
 * Problems view.
 */
export async function checkWorkspace(server: Server): Promise<void> {
  const client = server.running();
  if (!client) {
    return;
  }
  const found = await vscode.workspace.findFiles(
    '**/{*.mission,*.robot.xml,*.strategy.xml,*.taskgraph.xml,semo.toml}',
    '**/{node_modules,target,.git}/**',
  );
  await client.sendNotification('workspace/didChangeWatchedFiles', {
    changes: found.map((uri) => ({ uri: uri.toString(), type: 2 /* Changed */ })),
  });
  server.output.appendLine(`[info] Check Workspace: ${found.length} files sent to the server`);
  await vscode.commands.executeCommand('workbench.actions.view.problems');
  void vscode.window.setStatusBarMessage(`SeMo: checking ${found.length} files`, 3000);
}
