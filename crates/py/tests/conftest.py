"""Shared fixtures: the real data (`../shared/data`, or INBETWEEN_DATA) and the CLI binary."""

from __future__ import annotations

import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


def data_dir() -> pathlib.Path:
    env = os.environ.get("INBETWEEN_DATA")
    return pathlib.Path(env) if env else ROOT.parent / "shared" / "data"


def need(path: pathlib.Path) -> pathlib.Path:
    if not path.exists():
        pytest.skip(f"skipped: no data at {path}")
    return path


@pytest.fixture(scope="session")
def data() -> pathlib.Path:
    return data_dir()


@pytest.fixture(scope="session")
def cmu_bvh() -> pathlib.Path:
    return need(data_dir() / "mocap" / "cmu" / "cgspeed" / "131_01.bvh")


@pytest.fixture(scope="session")
def long_bvh() -> pathlib.Path:
    return need(data_dir() / "mocap" / "cmu" / "cgspeed" / "01_01.bvh")


@pytest.fixture(scope="session")
def cmu_amc() -> pathlib.Path:
    return need(data_dir() / "mocap" / "cmu" / "asf_amc" / "01_01.amc")


@pytest.fixture(scope="session")
def livelink_csv() -> pathlib.Path:
    return need(data_dir() / "face" / "neurosync" / "livelink" / "Happy" / "Happy.csv")


@pytest.fixture(scope="session")
def mp4() -> pathlib.Path:
    return need(data_dir() / "video" / "carphone_pristine.mp4")


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    """The `inbetween` binary of the same build (INBETWEEN_BIN), for byte-for-byte comparisons."""
    env = os.environ.get("INBETWEEN_BIN")
    if not env or not pathlib.Path(env).is_file():
        pytest.skip("skipped: no inbetween binary (set INBETWEEN_BIN)")
    return pathlib.Path(env)
