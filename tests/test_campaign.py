"""yade_electro.post.campaign: a yade-batch campaign's job logs into one table. The parsing on logs in
yade-batch's format (OK, FAILED, unfinished, no JSON line), and a real two-job campaign run by
``yade-electro batch`` into a log directory that did not exist, gathered by ``yade-electro gather``."""
import json
import os
import subprocess

import pandas as pd
import pytest

from conftest import repo_env

from yade_electro.post.campaign import gather, main, markdown_table, read_job_log, results_table

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SUMMARY = """
=================== JOB SUMMARY ================
id      : {id}
status  : {code} ({word})
duration: 00:01:05
command : yade-electro -x script.py
started : Wed Dec  2 06:49:40 2026
finished: Wed Dec  2 06:50:45 2026
"""


def _log(path, body, job=None, code=None):
    text = body
    if job is not None:
        text += SUMMARY.format(id=job, code=code, word="OK" if code == 0 else "FAILED")
    path.write_text(text)
    return str(path)


def test_read_job_logs_of_every_kind(tmp_path):
    ok = _log(tmp_path / "a.log", 'progress\n{"case": "x", "n": 5, "inner": {"a": 1.5}, "v": [1, 2]}\nBye.\n',
              job="a", code=0)
    failed = _log(tmp_path / "b.log", "Traceback ...\nValueError: bad\n", job="b", code=256)
    running = _log(tmp_path / "c.log", '{"partial": 1}\nstill going\n')
    silent = _log(tmp_path / "d.log", "no figures\n", job="d", code=0)
    jobs = {j.job: j for j in gather(str(tmp_path / "*.log"))}
    assert set(jobs) == {"a", "b", "c", "d"}
    assert jobs["a"].ok and jobs["a"].duration_s == 65.0 and jobs["a"].figures["inner"] == {"a": 1.5}
    assert jobs["b"].status == "FAILED" and jobs["b"].exit_status == 256 and not jobs["b"].ok
    assert jobs["c"].status == "unfinished" and jobs["c"].figures == {"partial": 1}
    assert jobs["d"].status == "OK" and jobs["d"].figures is None and not jobs["d"].ok
    assert read_job_log(ok).log == ok and read_job_log(failed).figures is None
    df = results_table(jobs[k] for k in "abcd")
    assert list(df.columns[:5]) == ["job", "status", "exit_status", "duration_s", "log"]
    assert df.loc[0, "inner.a"] == 1.5 and json.loads(df.loc[0, "v"]) == [1, 2]
    assert pd.isna(df.loc[1, "n"]) and df.loc[3, "status"] == "OK (no JSON)"
    md = markdown_table(df[["job", "n"]])
    assert md.splitlines()[0] == "| job | n |" and md.splitlines()[2] == "| a | 5 |"
    assert running and silent


def test_gather_cli_exit_codes(tmp_path, capsys):
    _log(tmp_path / "a.log", '{"n": 1}\n', job="a", code=0)
    assert main([str(tmp_path / "a.log"), "--out", str(tmp_path / "t.csv")]) == 0
    assert pd.read_csv(tmp_path / "t.csv")["n"].tolist() == [1]
    _log(tmp_path / "b.log", "crash\n", job="b", code=1)
    assert main([str(tmp_path)]) == 1                            # a failed job: exit 1
    assert "1 of 2 job(s) failed" in capsys.readouterr().err
    assert main([str(tmp_path), "--allow-failed"]) == 0
    assert main([str(tmp_path / "nothing*.log")]) == 2            # a pattern matching nothing
    assert "no log matches" in capsys.readouterr().err
    assert main([str(tmp_path / "a.log"), "--columns", "job,zzz"]) == 2
    assert "no column 'zzz'" in capsys.readouterr().err


def test_campaign_through_yade_batch_and_gather(tmp_path, yade_exe):
    table = tmp_path / "sweep.table"
    table.write_text("description n seed law\nc600 600 1 'continuum'\nv600 600 1 'voronoi'\n")
    logs = tmp_path / "not" / "yet"                                # made by yade-electro batch
    case = os.path.join(ROOT, "cases", "rod_resistance.py")
    p = subprocess.run(yade_exe + ["batch", "-j", "2", "--job-threads", "1", "--log", f"{logs}/@.log",
                                   str(table), case], cwd=tmp_path, env=repo_env(), stdin=subprocess.DEVNULL,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    out = tmp_path / "sweep.csv"
    g = subprocess.run(yade_exe + ["gather", f"{logs}/*.log", "--out", str(out)], env=repo_env(),
                       capture_output=True, text=True, timeout=120)
    assert g.returncode == 0, g.stdout + g.stderr
    df = pd.read_csv(out).set_index("job")
    assert sorted(df.index) == ["c600", "v600"] and (df["status"] == "OK").all()
    assert df.loc["c600", "law"] == "continuum" and df.loc["v600", "law"] == "voronoi"
    assert (df["n_target"] == 600).all()
    assert abs(df.loc["v600", "error_pct"]) < 3.0 < df.loc["c600", "error_pct"]


@pytest.mark.parametrize("args, made", [
    (["--log", "{d}/x/$.@.log", "t.table", "cases/s.py"], "{d}/x/cases"),
    (["--log={d}/y/@.log", "t.table", "s.py"], "{d}/y"),
])
def test_batch_makes_its_log_directories(tmp_path, args, made):
    from yade_electro.yade.launcher import made_log_directories
    args = [a.format(d=tmp_path) for a in args]
    assert made_log_directories(args) == [made.format(d=tmp_path)]
    assert os.path.isdir(made.format(d=tmp_path))
