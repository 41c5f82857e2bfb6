"""Gather a ``yade-batch`` campaign: every job's final JSON line into one table.

Every case script ends by printing one JSON line of its figures; ``yade-batch`` writes each
job's output to its log (``--log '/dir/$.@.log'``: script name, then the table's description
column) and appends a *JOB SUMMARY* (id, exit status, duration). :func:`gather` reads the
logs and :func:`results_table` puts one row per job in a pandas DataFrame: the job's id,
status, exit status, duration [s] and log, then the figures of its JSON line (nested
objects flattened to ``outer.inner`` columns, lists kept as JSON text).

From the command line (after ``yade-electro batch -j 2 --log '/tmp/sweep/$.@.log' table script.py``)::

    yade-electro gather '/tmp/sweep/*.log' --out sweep.csv [--columns job,n,law,error_pct]

It prints one line per job, writes the CSV (or Markdown for ``.md``), and exits 1 when a job
failed or printed no JSON line (``--allow-failed`` to exit 0 anyway): ``yade-batch`` itself
exits 0 when jobs fail. Never imports YADE.
"""
from __future__ import annotations

import argparse
import dataclasses
import glob
import json
import os
import re
import sys
from typing import Iterable, List, Optional

__all__ = ["JobResult", "read_job_log", "gather", "results_table", "markdown_table", "main"]

_SUMMARY = "=================== JOB SUMMARY ================"


@dataclasses.dataclass(frozen=True)
class JobResult:
    """One job of a campaign, read from its log.

    Attributes
    ----------
    status : str
        'OK', 'FAILED' (yade-batch's summary), or 'unfinished' (no summary: still running,
        killed, or a log not written by yade-batch).
    figures : dict or None
        The job's last JSON object line, or None when it printed none.
    duration_s : float or None
        From the summary [s], None when unfinished.
    """
    log: str
    job: str
    status: str
    exit_status: Optional[int]
    duration_s: Optional[float]
    figures: Optional[dict]

    @property
    def ok(self) -> bool:
        """Finished with exit status 0 and printed its figures."""
        return self.status == "OK" and self.figures is not None


def _last_json_object(lines) -> Optional[dict]:
    for line in reversed(lines):
        line = line.strip()
        if line.startswith("{"):
            try:
                obj = json.loads(line)
            except (ValueError, RecursionError):        # not JSON, or nested beyond the parser's depth
                continue
            if isinstance(obj, dict):
                return obj
    return None


def read_job_log(path: str) -> JobResult:
    """The :class:`JobResult` of one ``yade-batch`` log (or any log ending in a JSON line)."""
    with open(path, errors="replace") as fh:
        text = fh.read()
    head, sep, summary = text.rpartition(_SUMMARY)
    body = head if sep else text
    job = os.path.basename(path)
    job = job[:-4] if job.endswith(".log") else job
    status, exit_status, duration = "unfinished", None, None
    if sep:
        m = re.search(r"^id\s*:\s*(.*)$", summary, re.M)
        if m:
            job = m.group(1).strip()
        m = re.search(r"^status\s*:\s*(-?\d+)\s*\((\w+)\)", summary, re.M)
        if m:
            exit_status, status = int(m.group(1)), m.group(2)
        m = re.search(r"^duration:\s*(\d+):(\d+):(\d+)", summary, re.M)
        if m:
            h, mi, s = (int(g) for g in m.groups())
            duration = float(3600 * h + 60 * mi + s)
    return JobResult(log=str(path), job=job, status=status, exit_status=exit_status, duration_s=duration,
                     figures=_last_json_object(body.splitlines()))


def _expand(paths: Iterable[str]) -> List[str]:
    out = []
    for p in paths:
        hits = sorted(glob.glob(p)) if any(ch in p for ch in "*?[") else [p]
        if not hits:
            raise FileNotFoundError(f"no log matches {p!r}: give the --log pattern of the yade-batch run "
                                    "(e.g. '/tmp/sweep/*.log')")
        for h in hits:
            if os.path.isdir(h):
                out.extend(sorted(glob.glob(os.path.join(h, "*.log"))))
            elif not os.path.isfile(h):
                raise FileNotFoundError(f"log {h!r} not found")
            else:
                out.append(h)
    if not out:
        raise FileNotFoundError(f"no .log files in {list(paths)!r}")
    return list(dict.fromkeys(out))


def gather(paths: Iterable[str]) -> List[JobResult]:
    """Read every log named by ``paths`` (files, directories of ``*.log``, or glob patterns)."""
    return [read_job_log(p) for p in _expand([paths] if isinstance(paths, str) else paths)]


#: figures nested deeper than this stay one JSON-text column
MAX_DEPTH = 8


def _flatten(d: dict, prefix: str = "", depth: int = 0) -> dict:
    out = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict) and depth < MAX_DEPTH:
            out.update(_flatten(v, key + ".", depth + 1))
        elif isinstance(v, dict):
            out[key] = json.dumps(v)
        elif isinstance(v, list):
            out[key] = json.dumps(v)
        else:
            out[key] = v
    return out


def results_table(jobs: Iterable[JobResult]):
    """A pandas DataFrame, one row per job: job, status, exit_status, duration_s, log, then
    the flattened figures (missing figures stay empty, NaN)."""
    import pandas as pd
    rows = []
    for j in jobs:
        row = {"job": j.job, "status": j.status if j.figures is not None or j.status != "OK" else "OK (no JSON)",
               "exit_status": j.exit_status, "duration_s": j.duration_s, "log": j.log}
        if j.figures is not None:
            for k, v in _flatten(j.figures).items():
                row[k if k not in row else f"figures.{k}"] = v
        rows.append(row)
    return pd.DataFrame(rows)


def markdown_table(df) -> str:
    """The DataFrame as a Markdown table (floats to 6 significant digits, empty cells blank)."""
    def cell(v):
        if v is None or (isinstance(v, float) and v != v):
            return ""
        if isinstance(v, float):
            return f"{v:.6g}"
        return str(v).replace("|", "\\|")
    lines = ["| " + " | ".join(map(str, df.columns)) + " |", "|" + "---|" * len(df.columns)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in df.itertuples(index=False)]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="yade-electro gather",
                                 description="Gather the final JSON lines of a yade-batch campaign's job logs into one table.")
    ap.add_argument("logs", nargs="+", help="log files, directories, or glob patterns (quote them)")
    ap.add_argument("--out", help="write the table here (.csv, or .md for Markdown); default: print it")
    ap.add_argument("--columns", help="comma-separated columns to keep, in this order (default: all)")
    ap.add_argument("--allow-failed", action="store_true", help="exit 0 even when a job failed or printed no JSON line")
    args = ap.parse_args(argv)
    try:
        jobs = gather(args.logs)
    except FileNotFoundError as exc:
        print(f"yade-electro gather: {exc}", file=sys.stderr)
        return 2
    for j in jobs:
        what = "figures" if j.figures is not None else "NO JSON LINE"
        dur = "" if j.duration_s is None else f", {j.duration_s:.0f} s"
        print(f"{j.job}: {j.status}{dur}, {what} ({j.log})")
    df = results_table(jobs)
    if args.columns:
        cols = [c.strip() for c in args.columns.split(",") if c.strip()]
        unknown = [c for c in cols if c not in df.columns]
        if unknown:
            print(f"yade-electro gather: no column {', '.join(map(repr, unknown))}; the jobs give: "
                  + ", ".join(df.columns), file=sys.stderr)
            return 2
        df = df[cols]
    if args.out:
        if args.out.endswith(".md"):
            with open(args.out, "w") as fh:
                fh.write(markdown_table(df))
        else:
            df.to_csv(args.out, index=False)
        print(f"{len(jobs)} job(s) -> {args.out}")
    else:
        print(df.to_string(index=False))
    bad = [j for j in jobs if not j.ok]
    if bad:
        print(f"yade-electro gather: {len(bad)} of {len(jobs)} job(s) failed or printed no JSON line: "
              + ", ".join(j.job for j in bad), file=sys.stderr)
        return 0 if args.allow_failed else 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
