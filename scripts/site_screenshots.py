"""Screenshots of the built documentation site in headless Chromium (a developer's tool).

    mkdocs build --strict && python3 scripts/site_screenshots.py site \
        index.html=docs/site_start.png tutorials/pettingzoo_social/index.html=docs/site_tutorial.png

Serves SITE (the folder `mkdocs build` writes) on a free loopback port and saves a full-width
screenshot of the top of each PAGE=PNG. Needs the system Chromium (`chromium`, or
$MIMO_SOCIAL_CHROMIUM) and playwright (the dev extra; it downloads no browser).
"""

from __future__ import annotations

import argparse
import functools
import http.server
import os
import shutil
import threading
from pathlib import Path


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("site", help="the built site's folder")
    parser.add_argument("shots", nargs="+", metavar="PAGE=PNG",
                        help="a page of the site (its path) and the PNG to write")
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=900)
    args = parser.parse_args()
    shots = [s.split("=", 1) for s in args.shots]
    if any(len(s) != 2 for s in shots):
        parser.error("each shot is PAGE=PNG")
    exe = os.environ.get("MIMO_SOCIAL_CHROMIUM") or shutil.which("chromium")
    if not exe:
        parser.error("no chromium on the PATH (apt-get install chromium)")
    handler = functools.partial(_QuietHandler, directory=args.site)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    from playwright.sync_api import sync_playwright
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=exe, headless=True,
                                         args=["--no-sandbox", "--disable-gpu"])
            page = browser.new_page(viewport={"width": args.width, "height": args.height})
            for path, png in shots:
                url = f"http://127.0.0.1:{server.server_port}/{path}"
                page.goto(url, wait_until="networkidle")
                Path(png).parent.mkdir(parents=True, exist_ok=True)
                page.screenshot(path=png)
                print(f"wrote {png} ({url})")
            browser.close()
    finally:
        server.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
