"""The headless-browser check of a recording (a developer's check, not part of the package): does
Rerun's web viewer, in headless Chromium, show the bodies of a ``.rrd`` file in its 3D view, and
data in every other panel?

Run it with ``python3 scripts/check_viewer.py FILE.rrd`` (docs/viewer_check.md). ``check``: the
check itself (:func:`check_viewer`: pixels, colours, the 3D view found in a screenshot);
``panels``: the page's panels and which of them show no data; ``web_viewer``: the processes it
starts (a file server, ``rerun --web-viewer``, Chromium through Playwright, ``rerun rrd
filter``). Its tests: ``tests/recording/test_viewer_check.py`` (the browser ones are marked
slow).
"""

from .check import (HUE_TOLERANCE, MIN_PIXELS, SETTLE, TIMEOUT, ViewerCheck, check_viewer,
                    colour_pixels, find_3d_view, recording_colours, time_bar)
from .panels import SEPARATOR_RGB, empty_panels, is_empty_panel, panel_boxes
from .web_viewer import (ViewerCheckError, browser_missing, chromium_path, screenshot,
                         without_agents)

__all__ = ["HUE_TOLERANCE", "MIN_PIXELS", "SEPARATOR_RGB", "SETTLE", "TIMEOUT", "ViewerCheck",
           "ViewerCheckError", "browser_missing", "check_viewer", "chromium_path",
           "colour_pixels", "empty_panels", "find_3d_view", "is_empty_panel", "panel_boxes",
           "recording_colours", "screenshot", "time_bar", "without_agents"]
