"""Write docs/reference/cli.md from the commands' own help (typer/click): the command line
is the one source of its reference (tests/test_docs.py fails when the page differs).

    python docs/gen_cli.py
"""
from __future__ import annotations

from pathlib import Path

import click
import typer.main

from gearcli.cli import app

PAGE = Path(__file__).resolve().parent / "reference" / "cli.md"


def _param(p) -> str:
    option = getattr(p, "param_type_name", "") == "option"
    names = ", ".join(f"`{o}`" for o in p.opts) if option else f"`{p.metavar or p.name.upper()}`"
    meta = p.metavar if option and p.metavar else ""
    helptext = (getattr(p, "help", None) or "").replace("|", "\\|").replace("\n", " ")
    flag = getattr(p, "is_flag", False)
    default = "" if not option or flag or p.default is None else f" (default: `{p.default}`)"
    return f"| {names} | {'`' + meta + '`' if meta else ''} | {helptext}{default} |"


def page() -> str:
    group = typer.main.get_command(app)
    lines = ["# Command line", "", "Generated from the commands' own help by `docs/gen_cli.py` (a test fails when",
             "this page differs from it). Every command also answers `--help`.", ""]
    ctx = click.Context(group, info_name="gearcli")
    for name in group.list_commands(ctx):
        cmd = group.get_command(ctx, name)
        lines += [f"## `gearcli {name}`", "", " ".join((cmd.help or "").split()), "",
                  "| parameter | value | meaning |", "|---|---|---|"]
        lines += [_param(p) for p in cmd.params if p.name != "help"]
        lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    PAGE.write_text(page())
    print(f"wrote {PAGE}")
