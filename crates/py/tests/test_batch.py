"""inbetween.batch on a real Dask LocalCluster: the CMU corpus compressed by 2 worker processes gives
the CLI's outputs byte for byte, a worker killed mid-run loses no input, a bad file fails its line."""

from __future__ import annotations

import json
import os
import pathlib
import shutil
import subprocess
import threading

import pytest

import inbetween
import inbetween.batch

distributed = pytest.importorskip("dask.distributed", reason="skipped: no dask.distributed")


def takes(cmu: pathlib.Path) -> list:
    return sorted(p for p in cmu.rglob("*") if p.suffix.lower() in (".bvh", ".amc"))


def outputs(out: pathlib.Path) -> dict:
    return {
        str(p.relative_to(out)): p.read_bytes()
        for p in out.rglob("*")
        if p.is_file() and not p.name.startswith(("results-", "."))
    }


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        with distributed.Client(c) as client:
            yield client


def test_map_equals_the_cli_and_survives_a_killed_worker(cluster, data, cli, tmp_path):
    cmu = data / "mocap" / "cmu"
    if not cmu.is_dir():
        pytest.skip(f"skipped: no data at {cmu}")
    # A copy with one garbage file: the bad input fails its own line, not the run.
    lib = tmp_path / "lib"
    shutil.copytree(cmu, lib)
    (lib / "garbage.bvh").write_bytes(b"\xff\xfe not a bvh")
    paths = takes(lib)
    by_cli = tmp_path / "cli"
    subprocess.run(
        [str(cli), "batch", "mocap-compress", str(lib), "-o", str(by_cli), "--max-error", "1cm"],
        check=True, capture_output=True, env={**os.environ, "INBETWEEN_NO_PROGRESS": "1"},
    )
    by_dask = tmp_path / "dask"
    # Kill one worker process once the first results are in: its tasks go to the other worker.
    workers = list(cluster.scheduler_info()["workers"])
    killed = threading.Event()

    def progress(done, total):
        if done == 3 and not killed.is_set():
            killed.set()
            pid = cluster.run(os.getpid, workers=[workers[0]])[workers[0]]
            os.kill(pid, 9)

    lines = inbetween.batch.map("mocap-compress", paths, client=cluster, out=by_dask, root=lib, max_error_cm=1.0,
                                progress=progress)
    assert killed.is_set()
    assert [l["input"] for l in lines] == [str(p.relative_to(lib)) for p in paths]
    assert outputs(by_dask) == outputs(by_cli), "the same bytes as the CLI"
    bad = [l for l in lines if not l["ok"]]
    assert [l["input"] for l in bad] == ["garbage.bvh"] and "garbage.bvh" in bad[0]["error"]
    # The lines equal the CLI's but for timing, and the summary reads them.
    cli_lines = {}
    for f in by_cli.glob("results-*.jsonl"):
        for t in f.read_text().splitlines():
            l = json.loads(t)
            l["seconds"] = 0
            cli_lines[l["input"]] = l
    for l in lines:
        l = dict(l, seconds=0)
        assert l == cli_lines[l["input"]]
    dask_lines = (by_dask / inbetween.batch.RESULTS_FILE).read_text().splitlines()
    assert len(dask_lines) == len(paths), "one line per input, none lost or doubled by the kill"
    s = subprocess.run([str(cli), "batch", "summary", str(by_dask)], check=True, capture_output=True, text=True)
    assert f"{len(paths)} inputs" in s.stdout and "1 failed" in s.stdout, s.stdout


def test_run_input_and_bad_requests(tmp_path, cmu_bvh):
    line = inbetween.batch.run_input("mocap-keys", cmu_bvh, cmu_bvh.parent, tmp_path, max_error_cm=2.0)
    assert line["ok"], line
    keys = json.loads((tmp_path / (cmu_bvh.stem + ".keys.json")).read_text())
    assert keys["reconstruction"]["keys"]["frames"] == line["report"]["keys"]
    with pytest.raises(inbetween.InbetweenError, match="unknown batch job"):
        inbetween.batch.run_input("mocap-zip", cmu_bvh, cmu_bvh.parent, tmp_path)
    with pytest.raises(inbetween.InbetweenError, match="unknown option"):
        inbetween.batch.run_input("mocap-compress", cmu_bvh, cmu_bvh.parent, tmp_path, max_err=1)
    with pytest.raises(inbetween.InbetweenError, match="needs either an error bound"):
        inbetween.batch.run_input("mocap-compress", cmu_bvh, cmu_bvh.parent, tmp_path)
    with pytest.raises(inbetween.InbetweenError, match="not inside the root"):
        inbetween.batch.run_input("mocap-compress", cmu_bvh, tmp_path, tmp_path, max_error_cm=1.0)
    with pytest.raises(inbetween.InbetweenError, match="reads .amc, .bvh"):
        inbetween.batch.map("mocap-compress", [tmp_path / "a.txt"], max_error_cm=1.0)
