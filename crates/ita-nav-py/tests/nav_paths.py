"""What the tests that run the `nav-app` binary share: where the workspace and the shared data
are, the binary (`NAV_APP_BIN`, set by `cargo xtask python`), and a data file that is skipped
when missing — a failure under CI=true, as in every test that needs the data root."""

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
DATA = pathlib.Path(os.environ.get("ITA_NAV_DATA", ROOT.parent / "shared" / "data"))
SAMPLE = DATA / "udacity" / "solidWhiteRight-320x240-gray.y4m"


def exe():
    e = os.environ.get("NAV_APP_BIN")
    if not e:
        pytest.fail("NAV_APP_BIN is not set (cargo xtask test sets it to the nav-app binary)")
    return e


def data_file(path):
    """`path`, or a skip (a failure under CI=true) naming it when the shared data lacks it."""
    if not path.is_file():
        msg = f"no {path} (the shared data)"
        if os.environ.get("CI") == "true":
            pytest.fail(msg)
        pytest.skip(msg)
    return path
