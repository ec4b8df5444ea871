// The SeMo extension: the `semo lsp` client, the Robots panel, the Robots
// (live) view, and the palette's commands. Each part lives in its own module.

import * as vscode from 'vscode';
import { checkWorkspace, generateCode, newMission, verifyMission } from './commands';
import { GraphViews } from './graphView';
import { LiveRobotsView } from './liveRobotsView';
import { insertNode, RobotsView } from './robotsView';
import { Server } from './server';
import { SimulationViews } from './simulateView';

let server: Server | undefined;

export async function activate(context: vscode.ExtensionContext): Promise<void> {
  const output = vscode.window.createOutputChannel('SeMo');
  server = new Server(context, output);
  const robots = new RobotsView(server);
  const simulations = new SimulationViews(server);
  const live = new LiveRobotsView(server);
  const graphs = new GraphViews(server, live.onView);
  const s = server;
  s.onGenerateCode = (args) => generateCode(s, args);
  const robotsTree = vscode.window.createTreeView('semo.robots', { treeDataProvider: robots });
  robots.attach(robotsTree);
  const liveTree = vscode.window.createTreeView('semo.live', { treeDataProvider: live });
  context.subscriptions.push(
    output,
    server,
    robots,
    graphs,
    simulations,
    robotsTree,
    live,
    liveTree,
    vscode.commands.registerCommand('semo.restartServer', () => s.restart()),
    vscode.commands.registerCommand('semo.showOutput', () => output.show()),
    vscode.commands.registerCommand('semo.newMission', newMission),
    vscode.commands.registerCommand('semo.generate', () => generateCode(s)),
    vscode.commands.registerCommand('semo.showTaskGraph', () => graphs.show('taskgraph')),
    vscode.commands.registerCommand('semo.showModeMachine', () => graphs.show('modes')),
    vscode.commands.registerCommand('semo.checkWorkspace', () => checkWorkspace(s)),
    vscode.commands.registerCommand('semo.simulateMission', () => simulations.simulate()),
    vscode.commands.registerCommand('semo.verifyMission', () => verifyMission(s)),
    vscode.commands.registerCommand('semo.robots.refresh', () => robots.refresh()),
    vscode.commands.registerCommand('semo.robots.insert', insertNode),
    vscode.commands.registerCommand('semo.monitorRobots', () => live.start()),
    vscode.commands.registerCommand('semo.stopMonitoring', () => live.stop()),
    vscode.workspace.onDidChangeConfiguration((e) => {
      if (e.affectsConfiguration('semo.server')) {
        void vscode.window
          .showInformationMessage('The SeMo server settings changed.', 'Restart Server')
          .then((c) => c && s.restart());
      }
    }),
  );
  await server.start();
}

export async function deactivate(): Promise<void> {
  await server?.stop();
}
