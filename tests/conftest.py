import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BEARINGS = ROOT / "examples" / "bearings"


@pytest.fixture(scope="session")
def table1():
    from slewing_model import load_bearing

    return load_bearing(BEARINGS / "table1.toml")


@pytest.fixture(scope="session")
def table3():
    from slewing_model import load_bearing

    return load_bearing(BEARINGS / "table3.toml")


@pytest.fixture(autouse=True, scope="session")
def _cache_dir(tmp_path_factory):
    # superelements built by the tests go to a private cache, not the user's
    os.environ.setdefault("SLEWING_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
