// The language client: finds `semo`, starts `semo lsp`, keeps the status bar
// item in step with it, and restarts it on demand.

import * as fs from 'fs';
import * as os from 'os';
import * as vscode from 'vscode';
import {
  LanguageClient,
  LanguageClientOptions,
  ServerOptions,
  State,
} from 'vscode-languageclient/node';
import { DiscoveryEnv, findServer } from './pure/discovery';

/** The server's `workspace/executeCommand` name for code generation. */
export const GENERATE_CODE_COMMAND = 'semo.generateCode';

/** The files the server handles: missions, and three kinds of XML by name. */
export const DOCUMENT_SELECTOR = [
  { language: 'semo' },
  { language: 'xml', pattern: '**/*.strategy.xml' },
  { language: 'xml', pattern: '**/*.robot.xml' },
  { language: 'xml', pattern: '**/*.taskgraph.xml' },
  // A generated robot's task graph (`semo build` writes OUT/TEAM/ROBOT/taskgraph.xml).
  { language: 'xml', pattern: '**/taskgraph.xml' },
  // Scenario files: completion of the names of their mission.
  { language: 'json', pattern: '**/*.scenario.json' },
  // The project file, whatever language an installed extension gives TOML.
  { scheme: 'file', pattern: '**/semo.toml' },
];

function isExecutable(file: string): boolean {
  try {
    const stat = fs.statSync(file);
    if (!stat.isFile()) {
      return false;
    }
    if (process.platform !== 'win32') {
      fs.accessSync(file, fs.constants.X_OK);
    }
    return true;
  } catch {
    return false;
  }
}

export class Server implements vscode.Disposable {
  client: LanguageClient | undefined;
  private readonly status: vscode.StatusBarItem;
  private readonly changed = new vscode.EventEmitter<void>();
  /** Fires when a client becomes ready (the robot panel refreshes then). */
  readonly onReady = this.changed.event;
  /**
   * Runs `semo.generateCode` for a code lens with its arguments (set by the
   * extension to the palette's Generate Code flow).
   */
  onGenerateCode: ((args: unknown) => Promise<unknown>) | undefined;

  constructor(
    private readonly context: vscode.ExtensionContext,
    readonly output: vscode.OutputChannel,
  ) {
    this.status = vscode.window.createStatusBarItem(vscode.StatusBarAlignment.Left, 0);
    this.status.name = 'SeMo language server';
    this.status.command = 'semo.showOutput';
    this.setStatus('stopped');
    this.status.show();
  }

  private setStatus(state: 'starting' | 'ready' | 'error' | 'stopped', detail?: string): void {
    const look = {
      starting: ['$(sync~spin) SeMo', 'The SeMo server is starting'],
      ready: ['$(check) SeMo', 'The SeMo server is ready'],
      error: ['$(error) SeMo', 'The SeMo server is not running'],
      stopped: ['$(circle-slash) SeMo', 'The SeMo server is stopped'],
    }[state];
    this.status.text = look[0];
    this.status.tooltip = `${look[1]}${detail ? `: ${detail}` : ''} (click for the SeMo output)`;
    this.status.backgroundColor =
      state === 'error' ? new vscode.ThemeColor('statusBarItem.errorBackground') : undefined;
  }

  private discoveryEnv(): DiscoveryEnv {
    return {
      platform: process.platform,
      pathVar: process.env.PATH ?? '',
      extensionRoot: this.context.extensionPath,
      workspaceRoot: vscode.workspace.workspaceFolders?.[0]?.uri.fsPath,
      home: os.homedir(),
      isExecutable,
    };
  }

  async start(): Promise<void> {
    const config = vscode.workspace.getConfiguration('semo');
    const found = findServer(this.discoveryEnv(), config.get<string>('server.path'));
    if (found.kind === 'not-found') {
      this.setStatus('error', 'semo not found');
      this.output.appendLine(`[error] ${found.message}`);
      const open = 'Open Settings';
      const choice = await vscode.window.showErrorMessage(found.message, open, 'Show Output');
      if (choice === open) {
        await vscode.commands.executeCommand('workbench.action.openSettings', 'semo.server.path');
      } else if (choice === 'Show Output') {
        this.output.show();
      }
      return;
    }
    const extraArgs = config.get<string[]>('server.extraArgs') ?? [];
    this.output.appendLine(`[info] starting ${found.command} lsp (${found.source})`);
    const run = { command: found.command, args: ['lsp', ...extraArgs] };
    const serverOptions: ServerOptions = { run, debug: run };
    const clientOptions: LanguageClientOptions = {
      documentSelector: DOCUMENT_SELECTOR,
      outputChannel: this.output,
      // This client tells the user how a generation ended (one notification
      // per generation); the server then shows no message of its own for it.
      initializationOptions: { generateCodeOutcome: true },
      middleware: {
        // A code lens's "Generate code for TEAM" runs the same flow as the
        // palette's Generate Code (progress, the conflict modal, the outcome).
        executeCommand: (command, args, next) =>
          command === GENERATE_CODE_COMMAND && this.onGenerateCode
            ? this.onGenerateCode(args[0])
            : next(command, args),
      },
      // `semo.trace.server` is read by the client because its id is `semo`.
      initializationFailedHandler: (error) => {
        this.setStatus('error', String(error));
        return false;
      },
    };
    const client = new LanguageClient('semo', 'SeMo', serverOptions, clientOptions);
    client.onDidChangeState((e) => {
      if (e.newState === State.Starting) {
        this.setStatus('starting');
      } else if (e.newState === State.Running) {
        this.setStatus('ready');
        this.changed.fire();
      } else if (e.newState === State.Stopped) {
        this.setStatus(this.client === client ? 'error' : 'stopped', 'the server stopped');
      }
    });
    this.client = client;
    this.setStatus('starting');
    try {
      await client.start();
    } catch (e) {
      this.setStatus('error', String(e));
      this.output.appendLine(`[error] the server did not start: ${e}`);
      void vscode.window
        .showErrorMessage(`The SeMo server did not start: ${e}`, 'Show Output')
        .then((c) => c && this.output.show());
    }
  }

  async stop(): Promise<void> {
    const client = this.client;
    this.client = undefined;
    if (client) {
      try {
        await client.stop(2000);
      } catch (e) {
        this.output.appendLine(`[warn] stopping the server: ${e}`);
      }
      await client.dispose();
    }
    this.setStatus('stopped');
  }

  async restart(): Promise<void> {
    await this.stop();
    await this.start();
  }

  /** The running client, or a message saying why there is none. */
  running(): LanguageClient | undefined {
    if (this.client && this.client.state === State.Running) {
      return this.client;
    }
    void vscode.window
      .showWarningMessage('The SeMo server is not running.', 'Restart Server', 'Show Output')
      .then((c) => {
        if (c === 'Restart Server') {
          void this.restart();
        } else if (c === 'Show Output') {
          this.output.show();
        }
      });
    return undefined;
  }

  dispose(): void {
    void this.stop();
    this.status.dispose();
    this.changed.dispose();
  }
}
