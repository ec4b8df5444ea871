// What "SeMo: Simulate Mission" decides without VS Code: which scenario
// files go with a mission, which mission line a click on the timeline
// names, and the page that shows the timeline.

/** A scenario file's name ends so (the JSON Schema is attached to it too). */
export const SCENARIO_SUFFIX = '.scenario.json';

/**
 * The scenario files among `names` (a folder's entries, beside the
 * mission), the one named after the mission first (`scouting.mission` →
 * `scouting.scenario.json`), then by name.
 */
export function scenarioCandidates(missionFile: string, names: string[]): string[] {
  const stem = missionFile.replace(/\.mission$/, '');
  const own = stem + SCENARIO_SUFFIX;
  return names
    .filter((n) => n.endsWith(SCENARIO_SUFFIX))
    .sort((a, b) => (a === own ? -1 : b === own ? 1 : a < b ? -1 : a > b ? 1 : 0));
}

/**
 * The 0-based mission line a timeline element names: its `data-line`
 * attribute holds the 1-based line of the mode or plan that caused it
 * (0 or none: no line).
 */
export function missionLine(dataLine: string | null | undefined): number | undefined {
  if (dataLine === null || dataLine === undefined || !/^\d+$/.test(dataLine)) {
    return undefined;
  }
  const line = Number(dataLine);
  return line >= 1 ? line - 1 : undefined;
}

export function escapeHtml(text: string): string {
  return text.replace(
    /[&<>"]/g,
    (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[c]!,
  );
}

/**
 * The webview page: the summary, then the timeline SVG inline. One script
 * (allowed by its nonce alone) posts `{ line }` when an element carrying
 * `data-line` is clicked, so the extension opens the mission there.
 */
export function simulationPage(title: string, summary: string, svg: string, nonce: string): string {
  return `<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="default-src 'none'; style-src 'unsafe-inline'; img-src data:; script-src 'nonce-${nonce}';">
<title>${escapeHtml(title)}</title>
<style>
  body { background: #fff; color: #222; margin: 0; padding: 12px; font-family: sans-serif; }
  pre { font-size: 12px; }
  [data-line]:not([data-line="0"]) { cursor: pointer; }
  /* The timeline fits the view's width (it was clipped on the right), its viewBox scaling it,
     down to a width that stays readable; narrower, it scrolls. */
  .timeline { overflow-x: auto; }
  .timeline svg { width: 100%; min-width: 900px; height: auto; }
</style></head>
<body><pre class="summary">${escapeHtml(summary)}</pre>
<div class="timeline">${svg}</div>
<script nonce="${nonce}">
  const vscode = acquireVsCodeApi();
  document.addEventListener('click', (event) => {
    const element = event.target instanceof Element ? event.target.closest('[data-line]') : null;
    if (element) {
      vscode.postMessage({ line: element.getAttribute('data-line') });
    }
  });
</script></body></html>`;
}
