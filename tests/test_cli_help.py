"""``recipdyn --help`` lists every command with a whole sentence (issue 34, item 5)."""

import inspect

import typer

from recipdyn.cli import _register, app


def test_every_command_summary_is_one_unbroken_line(capsys, monkeypatch):
    """Typer's command list (rich markup mode) keeps the single line breaks of a docstring's
    first paragraph, which cut the summary mid-sentence ("... with the" / "crosshead ...").
    Each command's first paragraph must therefore be one line, ending a sentence, and the
    list must show it whole."""
    monkeypatch.setenv("COLUMNS", "250")
    _register()  # the commands register when their modules are imported
    cmd = typer.main.get_command(app)
    seen = 0
    for name, sub in cmd.commands.items():
        first = inspect.cleandoc(sub.help or "").split("\n\n")[0]
        assert first and "\n" not in first, (name, first)
        assert first.rstrip().endswith((".", ")")), (name, first)
        seen += 1
    assert seen >= 10
    try:
        cmd.main(["--help"], prog_name="recipdyn", standalone_mode=False)
    except SystemExit:
        pass
    out = capsys.readouterr().out
    for name, sub in cmd.commands.items():
        first = inspect.cleandoc(sub.help or "").split("\n\n")[0]
        assert first in out, name
