"""The README stands alone: its relative links and pictures resolve inside the repository,
and it sends no one outside it; CI (``.ci/run``) builds the documentation strictly."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)\)")
HTML_REF = re.compile(r'<(?:img|a)\b[^>]*?\b(?:src|href)="([^"]+)"')


def _slug(heading: str) -> str:
    """The anchor GitHub and MkDocs give a heading (lower case, punctuation dropped, spaces to
    hyphens)."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def _anchors(md: Path) -> set[str]:
    inside_code, out = False, set()
    for line in md.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            inside_code = not inside_code
        elif not inside_code and line.startswith("#"):
            out.add(_slug(line.lstrip("#")))
    return out


def _relative_links(md: Path) -> list[str]:
    """Markdown links and images, and HTML ``src``/``href``, outside code; no URLs."""
    text = re.sub(r"```.*?```", "", md.read_text(encoding="utf-8"), flags=re.S)
    text = re.sub(r"`[^`\n]*`", "", text)
    found = LINK.findall(text) + HTML_REF.findall(text)
    return list(dict.fromkeys(t for t in found if not re.match(r"[a-z][a-z0-9+.-]*:", t)))


def test_readme_has_relative_links_and_a_picture():
    links = _relative_links(README)
    assert any(t.startswith("docs/") and t.endswith(".md") for t in links), links
    assert any(t.endswith(".png") for t in links), "the README shows a picture"


@pytest.mark.parametrize("target", _relative_links(README))
def test_readme_relative_link_resolves(target):
    path, _, anchor = target.partition("#")
    file = (README.parent / path).resolve() if path else README
    assert file.is_relative_to(ROOT), f"{target} points outside the repository"
    assert file.exists(), f"README links to {target}, which does not exist"
    if file.suffix == ".png":
        assert file.stat().st_size < 200_000, f"{target} is over 200 KB"
    if anchor:
        assert file.suffix == ".md", target
        assert anchor in _anchors(file), f"{target}: no heading with anchor #{anchor}"


def test_readme_refers_to_nothing_outside_the_repository():
    text = README.read_text(encoding="utf-8")
    for outside in ("../shared", "shared/", "/work/", "seed 00", "seeds/"):
        assert outside not in text, f"the README mentions {outside!r}"


def test_readme_starts_with_the_two_commands():
    text = README.read_text(encoding="utf-8")
    block = re.search(r"```bash\n(.*?)```", text, flags=re.S)
    assert block is not None and text.index("```bash") < text.index("\n## ")
    lines = [ln for ln in block.group(1).splitlines() if ln.strip()]
    assert lines == [
        "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/boundest run satellite",
        "python3 -m venv .venv && .venv/bin/pip install -e '.[test]' && .venv/bin/python -m pytest",
    ]


def test_ci_builds_the_documentation_strictly_and_not_quietly():
    """``.ci/run`` builds the documentation with ``--strict`` and never ``--quiet``: mkdocs 1.6
    drops the warnings that --quiet hides before its strict-mode counter sees them, so a failing
    example or a broken link passed the build with both (checked by hand with mkdocs 1.6.1)."""
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    builds = [ln for ln in ci.splitlines()
              if "mkdocs build" in ln and not ln.lstrip().startswith("#")]
    assert builds, "no documentation build in .ci/run"
    for line in builds:
        assert "--strict" in line and "--quiet" not in line and " -q" not in line, line
