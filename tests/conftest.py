"""Test-session isolation: the tests never read or write the user's own passmd cache.

The result cache's default folder is the user's cache folder (platformdirs: under
``$XDG_CACHE_HOME`` on Linux). The session points ``XDG_CACHE_HOME`` at a folder of its own,
inherited by every command-line subprocess, so a test that runs with the default cache, or
runs ``passmd cache clear`` on it, touches that folder only.
"""

import os
import shutil
import tempfile

_SESSION_CACHE_HOME = tempfile.mkdtemp(prefix="passmd-tests-xdg-cache-")
_user_cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
if os.path.isdir(os.path.join(_user_cache, "matplotlib")):  # matplotlib keeps its font cache there too
    shutil.copytree(os.path.join(_user_cache, "matplotlib"), os.path.join(_SESSION_CACHE_HOME, "matplotlib"))
os.environ["XDG_CACHE_HOME"] = _SESSION_CACHE_HOME


def pytest_sessionfinish(session, exitstatus):
    shutil.rmtree(_SESSION_CACHE_HOME, ignore_errors=True)
