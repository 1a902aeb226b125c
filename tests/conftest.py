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


@pytest.fixture(scope="session")
def table3_fmu(tmp_path_factory):
    """The bearing FMU of table3 with synthetic errors (coarse superelement, free rings), built once."""
    import sys

    sys.path.insert(0, str(ROOT))
    from build_fmu import build_fmu

    path = tmp_path_factory.mktemp("fmu") / "SlewingBearing_table3.fmu"
    return build_fmu(BEARINGS / "table3_errors.toml", path, mesh="coarse", bc="free")
