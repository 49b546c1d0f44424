"""The report page in a real browser: renders cleanly and model text stays text."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from rover.report import build_report

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not os.path.exists("/usr/bin/chromium"), reason="needs Debian chromium"),
]
pytest.importorskip("websockets")

INJECTION = "<script>document.title='pwned'</script>"


def test_page_renders_without_errors_and_injection_stays_text(
    make_run, open_in_chromium, tmp_path: Path
) -> None:
    index = build_report(make_run(), tmp_path / "report")
    page = open_in_chromium(index)
    assert page.errors == []
    assert page.broken_images == []
    assert page.title.startswith("rover report")
    assert "pwned" not in page.title
    assert INJECTION in page.text  # shown to the reader, as text
    assert page.scripts == 0
    assert "ORACLE OUTPUT — answers come from simulator ground truth, not a VLM" in page.text
    assert page.screenshot[:8] == b"\x89PNG\r\n\x1a\n"
    (tmp_path / "screenshot.png").write_bytes(page.screenshot)
