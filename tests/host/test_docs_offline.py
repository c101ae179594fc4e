"""The built documentation site read from disk, as a reader who opens build/site/index.html in
Chromium would: links open pages (not folder listings), search works without a server."""

import os
import pathlib
import subprocess
import sys

import pytest
from test_yamcs_browser import CHROMIUM, CHROMIUM_FLAGS, browser_missing, sync_playwright

ROOT = pathlib.Path(__file__).resolve().parents[2]
MISSING = browser_missing()


@pytest.mark.skipif(MISSING is not None, reason=str(MISSING))
def test_the_site_opens_from_disk_and_its_links_work(tmp_path):
    site = tmp_path / "site"
    r = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "--site-dir", str(site)],
        cwd=ROOT, env=dict(os.environ, NO_MKDOCS_2_WARNING="1"), capture_output=True, text=True,
        timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, headless=True, args=CHROMIUM_FLAGS)
        try:
            page = browser.new_page()
            page.goto((site / "index.html").as_uri())
            page.get_by_role("link", name="Getting started").first.click()
            page.wait_for_load_state()
            assert page.url.endswith("/getting-started.html"), page.url
            assert "Getting started" in page.locator("h1").first.inner_text()
            page.get_by_role("link", name="Architecture").first.click()
            page.wait_for_load_state()
            assert page.url.endswith("/architecture.html"), page.url
            assert "Index of" not in page.content()  # never a folder listing
        finally:
            browser.close()
