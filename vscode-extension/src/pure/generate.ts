// "Generate Code" and the server's refusal to replace files a user changed
// (issue 21): the decision, without VS Code, so that it is unit-tested.

/** A file generation would replace that is not as semo wrote it. */
export interface Conflict {
  path: string;
  why: string;
}

/**
 * The server's refusal of `semo.generateCode` over files in the way: its
 * message (what it would replace and how forcing saves them) and the files.
 */
export interface ConflictRefusal {
  message: string;
  conflicts: Conflict[];
}

/** The arguments of `semo.generateCode` (see the server's `generate_code.rs`). */
export interface GenerateArguments {
  uri: string;
  outputFolder?: string;
  /** Every robot's target; else each robot's own (the server's build plan). */
  target?: string;
  /** Each robot's platform simulated (`semo build --sim`). */
  sim?: boolean;
  team?: string;
  force?: boolean;
}

/**
 * The refusal carried by a failed request: the JSON-RPC error's `data` holds
 * `conflicts` only when generation stopped over files in the way; every other
 * failure gives `undefined`.
 */
export function conflictRefusal(error: unknown): ConflictRefusal | undefined {
  if (typeof error !== 'object' || error === null) {
    return undefined;
  }
  const { message, data } = error as { message?: unknown; data?: unknown };
  const conflicts = (data as { conflicts?: unknown } | null | undefined)?.conflicts;
  if (!Array.isArray(conflicts) || conflicts.length === 0) {
    return undefined;
  }
  const files: Conflict[] = [];
  for (const c of conflicts) {
    const { path, why } = (c ?? {}) as { path?: unknown; why?: unknown };
    if (typeof path !== 'string') {
      return undefined;
    }
    files.push({ path, why: typeof why === 'string' ? why : '' });
  }
  return { message: typeof message === 'string' ? message : '', conflicts: files };
}

/** The modal's one action: the server saves the files under `.semo-backup/` first. */
export const BACK_UP_AND_REGENERATE = 'Back up and regenerate';

/** The modal's question and its detail (one line per file in the way). */
export function forcePrompt(refusal: ConflictRefusal): { message: string; detail: string } {
  const n = refusal.conflicts.length;
  return {
    message:
      n === 1
        ? 'Generating would replace a file that is not as SeMo wrote it.'
        : `Generating would replace ${n} files that are not as SeMo wrote them.`,
    detail:
      refusal.conflicts.map((c) => (c.why ? `${c.path}: ${c.why}` : c.path)).join('\n') +
      '\n\nNothing was written. "' +
      BACK_UP_AND_REGENERATE +
      '" first saves them under .semo-backup/ in the output folder.',
  };
}

/** How a generation ended. */
export type Outcome =
  | { kind: 'done'; value: unknown; forced: boolean }
  | { kind: 'declined'; refusal: ConflictRefusal }
  | { kind: 'failed'; error: unknown };

/**
 * Sends `semo.generateCode` with `args`; when the server refuses over files
 * in the way, asks `askToForce` and, only if it agrees, sends the same
 * arguments again with `force: true`. Never forces without being asked.
 */
export async function generateWithConsent(
  send: (args: GenerateArguments) => PromiseLike<unknown>,
  args: GenerateArguments,
  askToForce: (refusal: ConflictRefusal) => Promise<boolean>,
): Promise<Outcome> {
  try {
    return { kind: 'done', value: await send(args), forced: args.force === true };
  } catch (error) {
    const refusal = args.force ? undefined : conflictRefusal(error);
    if (!refusal) {
      return { kind: 'failed', error };
    }
    if (!(await askToForce(refusal))) {
      return { kind: 'declined', refusal };
    }
    try {
      return { kind: 'done', value: await send({ ...args, force: true }), forced: true };
    } catch (again) {
      return { kind: 'failed', error: again };
    }
  }
}
