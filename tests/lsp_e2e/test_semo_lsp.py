"""`semo lsp` as an editor meets it: the real binary over stdio, driven by
pytest-lsp (an independent client built on pygls). SEMO_BIN names the binary."""

import os

import pytest_lsp
from lsprotocol import types
from pytest_lsp import ClientServerConfig, LanguageClient

URI = "file:///e2e/patrol.mission"
MISSION = """{
  Base: iRobotCreate base
}
Base.Action.Go{
  mvoe("1,1")
} repeat()
Base.GO{ set(Action, Go) }
Base.main{ default: mode = GO }
"""


@pytest_lsp.fixture(
    config=ClientServerConfig(server_command=[os.environ["SEMO_BIN"], "lsp", "--stdio"])
)
async def client(lsp_client: LanguageClient):
    await lsp_client.initialize_session(
        types.InitializeParams(
            capabilities=types.ClientCapabilities(
                general=types.GeneralClientCapabilities(
                    position_encodings=[types.PositionEncodingKind.Utf16]
                ),
                text_document=types.TextDocumentClientCapabilities(
                    completion=types.CompletionClientCapabilities(
                        completion_item=types.ClientCompletionItemOptions(
                            snippet_support=True,
                            documentation_format=[types.MarkupKind.Markdown],
                        )
                    )
                ),
            )
        )
    )
    yield
    await lsp_client.shutdown_session()


def open_mission(client: LanguageClient, text: str, version: int = 1):
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(
                uri=URI, language_id="mission", version=version, text=text
            )
        )
    )


async def diagnostics_for_version(client: LanguageClient, version: int):
    while True:
        params = await client.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
        if params.uri == URI and params.version == version:
            return params.diagnostics


async def test_a_mission_with_an_error_gets_its_diagnostic_then_a_fix_clears_it(
    client: LanguageClient,
):
    open_mission(client, MISSION)
    diagnostics = await diagnostics_for_version(client, 1)
    assert [d.code for d in diagnostics] == ["E024"]
    assert "did you mean `move`?" in diagnostics[0].message
    assert diagnostics[0].range == types.Range(
        start=types.Position(line=4, character=2), end=types.Position(line=4, character=6)
    )

    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=URI, version=2),
            content_changes=[
                types.TextDocumentContentChangePartial(
                    range=types.Range(
                        start=types.Position(line=4, character=3),
                        end=types.Position(line=4, character=5),
                    ),
                    text="ov",
                )
            ],
        )
    )
    assert list(await diagnostics_for_version(client, 2)) == []


async def test_completion_offers_the_services_the_robots_have(client: LanguageClient):
    text = MISSION.replace('mvoe("1,1")', "mo")
    open_mission(client, text)
    await diagnostics_for_version(client, 1)
    result = await client.text_document_completion_async(
        types.CompletionParams(
            text_document=types.TextDocumentIdentifier(uri=URI),
            position=types.Position(line=4, character=4),
        )
    )
    items = result.items if isinstance(result, types.CompletionList) else result
    labels = [item.label for item in items]
    assert "move" in labels
    move = next(item for item in items if item.label == "move")
    # Snippets were offered by this client: the parameters are placeholders.
    assert move.insert_text_format == types.InsertTextFormat.Snippet
    assert move.text_edit.new_text.startswith("move($1")


async def test_rename_a_mode_everywhere_it_is_used(client: LanguageClient):
    open_mission(client, MISSION.replace("mvoe", "move"))
    assert list(await diagnostics_for_version(client, 1)) == []
    # `GO` in `Base.GO{ ... }`, line 6.
    at = types.Position(line=6, character=6)
    prepared = await client.text_document_prepare_rename_async(
        types.PrepareRenameParams(text_document=types.TextDocumentIdentifier(uri=URI), position=at)
    )
    assert prepared is not None
    edit = await client.text_document_rename_async(
        types.RenameParams(
            text_document=types.TextDocumentIdentifier(uri=URI), position=at, new_name="PATROL"
        )
    )
    changes = edit.changes[URI] if edit.changes else edit.document_changes[0].edits
    lines = MISSION.replace("mvoe", "move").split("\n")
    for change in sorted(changes, key=lambda c: (c.range.start.line, c.range.start.character), reverse=True):
        line = lines[change.range.start.line]
        start, end = change.range.start.character, change.range.end.character
        assert line[start:end] == "GO"
        lines[change.range.start.line] = line[:start] + change.new_text + line[end:]
    renamed = "\n".join(lines)
    assert "Base.PATROL{" in renamed and "mode = PATROL" in renamed
    assert "GO" not in renamed.replace("Go", "")
