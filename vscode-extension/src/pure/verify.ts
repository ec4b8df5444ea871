// "SeMo: Verify Mission": what the server's `semo.verify` answers, and what the
// user is told of it. No `vscode` import: unit-tested under plain Node.

/** The server's `workspace/executeCommand` name for `semo verify`. */
export const VERIFY_COMMAND = 'semo.verify';

/** A finding of `semo.verify` (docs/verify.md). */
export interface VerifyFinding {
  code: string;
  message: string;
  range: { start: { line: number; character: number } };
  scenario: string | null;
}

/** A property of the expectations file, judged over every behaviour. */
export interface VerifyProperty {
  expectation: string;
  verdict: 'holds' | 'broken' | 'not judged';
  proof: boolean;
  why: string | null;
  scenario: string | null;
}

/** What the server answers to `semo.verify`. */
export interface VerifyAnswer {
  exhaustive: boolean;
  states: number;
  summary: string;
  findings: VerifyFinding[];
  properties: VerifyProperty[];
}

/**
 * The one notification that sums a search up: its severity and text. A
 * finding or a broken property is a warning; a clean exhaustive search is a
 * proof, a clean bounded one only as far as it looked.
 */
export function verifyMessage(mission: string, answer: VerifyAnswer): {
  level: 'info' | 'warning';
  text: string;
} {
  const broken = answer.properties.filter((p) => p.verdict === 'broken').length;
  const findings = answer.findings.length;
  const reach = answer.exhaustive
    ? `every behaviour explored (${answer.states} states)`
    : `bounded search (${answer.states} states)`;
  if (findings === 0 && broken === 0) {
    return { level: 'info', text: `SeMo: ${mission}: nothing found, ${reach}` };
  }
  const parts = [];
  if (findings > 0) {
    parts.push(`${findings} finding(s)`);
  }
  if (broken > 0) {
    parts.push(`${broken} broken propert${broken === 1 ? 'y' : 'ies'}`);
  }
  return {
    level: 'warning',
    text: `SeMo: ${mission}: ${parts.join(', ')}, ${reach} (see the SeMo output)`,
  };
}
