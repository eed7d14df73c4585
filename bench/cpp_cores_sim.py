#!/usr/bin/env python3
"""The C++ stack's cold build on machines with more cores than this one, roc against colcon, replayed
from one traced build.

    .venv/bin/python bench/cpp_cores_sim.py [--cores 2,4,8,16,32,64] [--retrace]

On this machine's two cores both tools are CPU-bound (cpp_build_bench.py), so their schedules cannot
show. This replays the stack's build, job by job, on N simulated cores with each tool's policy:

1. **The trace** (once; ``--retrace`` again): roc builds a copy of the stack (``bench/.work/cpp/trace``)
   one package and one job at a time (``--parallel-workers 1``, ``-j1``) with a compiler and linker
   launcher (``bench/trace_launcher.sh``) that logs every compile and link. CMake's file API then gives
   each package's targets and which targets each one waits for.
2. **The model of a package**: its configure; then each target as make runs it (the make work before
   its compiles, which is code generation and dependency scanning, then its compiles side by side,
   then its link), once the targets it depends on are done; then the rest of make and the install.
   Work between logged jobs is charged to the target of the job after it.
3. **The replay on N cores**: R running processes on N cores each advance at min(1, N / R); both
   tools build N packages at once (``--parallel-workers N``, as the bench gives both 2).
   - roc: its ready queue (longest chain first, the weights a first build has); one jobserver of N:
     N - 1 tokens and each running make's own slot, the tokens taken in the order jobs became ready;
   - colcon: its topological order (by name among the ready); each make ``-jN`` (MAKEFLAGS set, as
     in cpp_build_bench.py), so up to N x N jobs share the cores;
   - colcon ``-jN -lN`` (colcon's own flags when MAKEFLAGS has none): a make starts a job beyond its
     first only while fewer than N processes run (the load read at once; the real one lags).
   - chain first: no tool's limits, every package as soon as its dependencies are done, N jobs at
     once, the job with the longest chain of work to the build's end first: a good schedule;
   - the bound no schedule of these jobs beats: all the work over N; the longest chain; for each
     package, the soonest it can be done plus the work of every package waiting for it, over N.
   The replay charges nothing for running more processes than cores (caches, memory): the measured
   builds show that cost, the replay does not.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

from cpp_build_bench import BIN, OVERRIDE, RELEASE, WORK, environment, fresh  # noqa: E402

from roc.builder.estimate import estimated_seconds  # noqa: E402
from roc.engine.ready import ReadyQueue, Task  # noqa: E402
from roc.workspace.load import discover_workspace  # noqa: E402

TRACE = WORK / "trace"
JOBS_LOG = WORK / "trace-jobs.jsonl"
LAUNCHER = HERE / "trace_launcher.sh"


# --- the trace ---------------------------------------------------------------------------------------

def trace() -> None:
    """roc builds a fresh copy of the stack, one job at a time, every compile and link logged."""
    ws = fresh("trace")
    JOBS_LOG.unlink(missing_ok=True)
    env = {**environment(), "ROC_TRACE_LOG": str(JOBS_LOG), "MAKEFLAGS": "-j1"}
    launchers = [f"-DCMAKE_{lang}_{tool}_LAUNCHER={LAUNCHER};{kind}"
                 for lang in ("C", "CXX") for tool, kind in (("COMPILER", "compile"), ("LINKER", "link"))]
    command = [str(BIN / "roc"), "work", "build", "--parallel-workers", "1", *OVERRIDE, *RELEASE, *launchers]
    print(f"tracing the stack's build in {ws}, one job at a time ...", end="", flush=True)
    start = time.perf_counter()
    result = subprocess.run(command, cwd=ws, env=env, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"\n{' '.join(command)} failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")
    print(f" {time.perf_counter() - start:.0f} s")
    query_targets(ws, env)


def query_targets(ws: Path, env: dict[str, str]) -> None:
    """Each package's CMake file API reply (its targets and their dependencies), by configuring again."""
    for build in sorted((ws / "build").iterdir()):
        if (build / "CMakeCache.txt").exists():
            query = build / ".cmake" / "api" / "v1" / "query"
            query.mkdir(parents=True, exist_ok=True)
            (query / "codemodel-v2").touch()
            subprocess.run(["cmake", "."], cwd=build, env=env, capture_output=True, check=True)


def cmake_targets(build: Path) -> tuple[dict[str, set[str]], dict[str, str]]:
    """A package's targets, each with the targets it depends on, and its artefacts' paths to their target."""
    reply = build / ".cmake" / "api" / "v1" / "reply"
    index = json.loads(max(reply.glob("index-*.json")).read_text())
    codemodel = next(o for o in index["objects"] if o["kind"] == "codemodel")
    targets = json.loads((reply / codemodel["jsonFile"]).read_text())["configurations"][0]["targets"]
    names = {t["id"]: t["name"] for t in targets}
    dependencies, artefacts = {}, {}
    for entry in targets:
        target = json.loads((reply / entry["jsonFile"]).read_text())
        dependencies[target["name"]] = {names[d["id"]] for d in target.get("dependencies", [])}
        for artefact in target.get("artifacts", []):
            artefacts[os.path.normpath(build / artefact["path"])] = target["name"]
    return dependencies, artefacts


# --- the model ---------------------------------------------------------------------------------------

class Job:
    """A process of a package's build: ``work`` seconds on a core of its own, after ``after``."""

    __slots__ = ("package", "work", "after", "in_make", "left", "ready_at")

    def __init__(self, package: str, work: float, in_make: bool) -> None:
        self.package, self.work, self.in_make = package, max(0.0, work), in_make
        self.after: list[Job] = []
        self.left = self.work
        self.ready_at = 0.0


def _events(ws: Path) -> list[dict]:
    return [json.loads(line) for line in (ws / "log" / "latest_build" / "events.log").read_text().splitlines()]


def _commands(ws: Path) -> dict[str, list[tuple[str, float, float]]]:
    """Each package's commands in order: (what, start, end), what being configure, make or install."""
    started: dict[tuple[str, str], float] = {}
    commands: dict[str, list[tuple[str, float, float]]] = {}
    for event in _events(ws):
        if event["event"] not in ("CommandStarted", "CommandEnded"):
            continue
        argv = event["command"]
        what = ("install" if "--install" in argv else "configure") if argv[0].endswith("cmake") else \
            "make" if argv[0].endswith("make") else "other"
        key = (event["task"], " ".join(argv))
        if event["event"] == "CommandStarted":
            started[key] = event["time"]
        else:
            commands.setdefault(event["task"], []).append((what, started.pop(key), event["time"]))
    return commands


def package_jobs(name: str, build: Path, commands: list[tuple[str, float, float]], logged: list[dict]) -> list[Job]:
    """The jobs of one package's build, from its commands and its logged compiles and links."""
    jobs: list[Job] = []
    make = next(((s, e) for what, s, e in commands if what == "make"), None)
    if make is None:  # not a make build: its commands one after another
        for _, start, end in commands:
            job = Job(name, end - start, in_make=False)
            job.after = jobs[-1:]
            jobs.append(job)
        return jobs
    configure = [Job(name, e - s, in_make=False) for what, s, e in commands if what == "configure"]
    dependencies, artefacts = cmake_targets(build)
    # each logged job's target: a compile's from its object's folder, a link's from its artefact
    previous_end, previous_target = make[0], None
    prelude: dict[str, float] = {}
    compiles: dict[str, list[float]] = {}
    links: dict[str, float] = {}
    for job in sorted(logged, key=lambda j: j["start"]):
        output = os.path.normpath(os.path.join(job["cwd"], job["out"]))
        target = artefacts.get(output) if job["kind"] == "link" else _object_target(job["out"])
        target = target or previous_target or "?"
        gap = max(0.0, job["start"] - previous_end)  # make's work, or a launcher's start before its clock
        if target != previous_target:  # the make work before a target's first job: code generation, scans
            prelude[target], gap = prelude.get(target, 0.0) + gap, 0.0
        if job["kind"] == "link":
            links[target] = links.get(target, 0.0) + gap + job["end"] - job["start"]
        else:
            compiles.setdefault(target, []).append(gap + job["end"] - job["start"])
        previous_end, previous_target = job["end"], target
    ends: dict[str, Job] = {}
    jobs += configure
    for target in _in_dependency_order(prelude, dependencies):
        first = Job(name, prelude[target], in_make=True)
        first.after = configure + [ends[d] for d in _logged_dependencies(target, dependencies, prelude)]
        body = [Job(name, seconds, in_make=True) for seconds in compiles.get(target, [])]
        for job in body:
            job.after = [first]
        end = Job(name, links.get(target, 0.0), in_make=True)
        end.after = body or [first]
        ends[target] = end
        jobs += [first, *body, end]
    rest = Job(name, make[1] - previous_end, in_make=True)
    rest.after = list(ends.values()) or configure
    install = [Job(name, e - s, in_make=False) for what, s, e in commands if what in ("install", "other")]
    for before, job in zip([rest, *install], install):  # one after another, as they ran
        job.after = [before]
    return jobs + [rest, *install]  # the last one ends the package


def _object_target(output: str) -> str | None:
    parts = Path(output).parts
    for index, part in enumerate(parts[:-1]):
        if part == "CMakeFiles" and parts[index + 1].endswith(".dir"):
            return parts[index + 1][:-4]
    return None


def _logged_dependencies(target: str, dependencies: dict[str, set[str]], logged: dict) -> set[str]:
    """The logged targets ``target`` waits for, through targets that ran no logged job."""
    found, stack, seen = set(), list(dependencies.get(target, ())), set()
    while stack:
        name = stack.pop()
        if name in seen:
            continue
        seen.add(name)
        if name in logged:
            found.add(name)
        else:
            stack.extend(dependencies.get(name, ()))
    return found


def _in_dependency_order(logged: dict, dependencies: dict[str, set[str]]) -> list[str]:
    order: list[str] = []
    placed: set[str] = set()

    def place(target: str, path: frozenset) -> None:
        if target in path:
            raise ValueError(f"targets in a cycle: {', '.join(sorted(path))}")
        if target in placed:
            return
        for dependency in sorted(_logged_dependencies(target, dependencies, logged)):
            place(dependency, path | {target})
        placed.add(target)
        order.append(target)

    for target in logged:
        place(target, frozenset())
    return order


def load_trace() -> tuple[dict[str, set[str]], dict[str, list[Job]], dict[str, float]]:
    """The stack's package graph, each package's jobs, and the weights roc's first build gives them."""
    if not JOBS_LOG.exists():
        sys.exit(f"{JOBS_LOG} is missing: run this with --retrace")
    packages = discover_workspace(TRACE)
    names = {p.name for p in packages}
    graph = {p.name: p.direct_dependencies() & names for p in packages}
    weights = {p.name: estimated_seconds(TRACE / p.path) for p in packages}
    logged: dict[str, list[dict]] = {}
    builds = TRACE / "build"
    for line in JOBS_LOG.read_text().splitlines():
        job = json.loads(line)
        package = Path(job["cwd"]).relative_to(builds).parts[0]
        logged.setdefault(package, []).append(job)
    commands = _commands(TRACE)
    jobs = {name: package_jobs(name, builds / name, commands[name], logged.get(name, [])) for name in graph}
    return graph, jobs, weights


# --- the replay --------------------------------------------------------------------------------------

POLICIES = ("roc", "colcon", "colcon -l", "chain first")


def colcon_order(graph: dict[str, set[str]]) -> list[str]:
    """colcon's topological order: of the packages whose dependencies are placed, the first by name."""
    order: list[str] = []
    while len(order) < len(graph):
        order.append(min(n for n, deps in graph.items() if n not in order and deps <= set(order)))
    return order


def _before(graph: dict[str, set[str]], jobs: dict[str, list[Job]]) -> dict[Job, list[Job]]:
    """The jobs each job waits for: within its package, and a package's first jobs the last job (the
    end) of each package it depends on."""
    return {job: job.after or [jobs[d][-1] for d in graph[name]] for name, js in jobs.items() for job in js}


def _dependents(before: dict[Job, list[Job]]) -> dict[Job, list[Job]]:
    """The jobs waiting for each job."""
    dependents: dict[Job, list[Job]] = {job: [] for job in before}
    for job, earlier_jobs in before.items():
        for earlier in earlier_jobs:
            dependents[earlier].append(job)
    return dependents


def chains_to_end(graph: dict[str, set[str]], jobs: dict[str, list[Job]]) -> dict[Job, float]:
    """Each job's longest chain of work to the build's end, across packages."""
    dependents = _dependents(_before(graph, jobs))
    chain: dict[Job, float] = {}
    for job in reversed(_job_order(dependents)):
        chain[job] = job.work + max((chain[d] for d in dependents[job]), default=0.0)
    return chain


def lower_bound(graph: dict[str, set[str]], jobs: dict[str, list[Job]], cores: int) -> float:
    """No schedule on ``cores`` cores ends sooner: all the work over the cores; the longest chain; and for
    each package, the soonest it can be done plus the work of the packages that wait for it (none of
    which can start before) over the cores."""
    before = _before(graph, jobs)
    finish: dict[Job, float] = {}
    for job in _job_order(_dependents(before)):
        finish[job] = job.work + max((finish[b] for b in before[job]), default=0.0)
    work = {name: sum(j.work for j in js) for name, js in jobs.items()}
    waiting = {name: {n for n in graph if name in _all_dependencies(graph, n)} for name in graph}
    after_package = max(finish[jobs[name][-1]] + sum(work[w] for w in waiting[name]) / cores for name in graph)
    return max(sum(work.values()) / cores, max(finish.values()), after_package)


def _all_dependencies(graph: dict[str, set[str]], name: str) -> set[str]:
    found, stack = set(), list(graph[name])
    while stack:
        dependency = stack.pop()
        if dependency not in found:
            found.add(dependency)
            stack.extend(graph[dependency])
    return found


def _job_order(dependents: dict[Job, list[Job]]) -> list[Job]:
    """The jobs, each before its dependents."""
    waiting = {j: 0 for j in dependents}
    for followers in dependents.values():
        for job in followers:
            waiting[job] += 1
    order = [j for j, count in waiting.items() if count == 0]
    for job in order:
        for follower in dependents[job]:
            waiting[follower] -= 1
            if waiting[follower] == 0:
                order.append(follower)
    return order


class Replay:
    """One build of the traced jobs on ``cores`` cores under one policy (POLICIES):

    - roc: ``cores`` packages at once from its ready queue; make jobs under one jobserver (N - 1 tokens,
      one slot of each make's own), tokens taken in the order jobs became ready;
    - colcon: ``cores`` packages at once in its topological order; each make -jN;
    - colcon -l: as colcon, a make's second job and more only while fewer than N processes run;
    - chain first: no tool's limits: every package as soon as its dependencies are done, N jobs at once,
      the job with the longest chain of work to the build's end first (what no tool driving make can
      do: make picks its own jobs). A good schedule, not the best: ``lower_bound`` bounds them all.
    """

    def __init__(self, graph: dict[str, set[str]], jobs: dict[str, list[Job]], weights: dict[str, float],
                 cores: int, policy: str) -> None:
        self.graph, self.jobs, self.cores, self.policy = graph, jobs, cores, policy
        self.queue = ReadyQueue({n: Task(n, deps, action=None, weight=weights[n]) for n, deps in graph.items()})
        self.order = colcon_order(graph)
        self.chain = chains_to_end(graph, jobs)
        self.rank = {job: index for index, job in enumerate(j for js in jobs.values() for j in js)}
        self.done: set[str] = set()
        self.pending: dict[str, list[Job]] = {}  # a package being built: its jobs not finished
        self.started: set[Job] = set()
        self.running: list[Job] = []
        self.now = 0.0

    def run(self) -> float:
        for package_jobs_ in self.jobs.values():
            for job in package_jobs_:
                job.left, job.ready_at = job.work, 0.0
        while len(self.done) < len(self.graph):
            self._start()
            if not self.running:
                raise RuntimeError(f"{self.policy} on {self.cores} cores: nothing runs")
            rate = min(1.0, self.cores / len(self.running))
            step = min(j.left for j in self.running) / rate
            self.now += step
            for job in self.running:
                job.left -= step * rate
            for job in [j for j in self.running if j.left <= 1e-9]:
                self.running.remove(job)
                self._finish(job)
        return self.now

    def _start(self) -> None:
        """Start packages and jobs until the policy allows no more (a job of no work ends at once)."""
        while True:
            self._start_packages()
            for job in self._ready_jobs():
                if self._allowed(job):
                    self.started.add(job)
                    if job.left > 0:
                        self.running.append(job)
                    else:
                        self._finish(job)
                        break
            else:
                return

    def _start_packages(self) -> None:
        limit = len(self.graph) if self.policy == "chain first" else self.cores
        while len(self.pending) < limit:
            if self.policy in ("roc", "chain first"):
                if not self.queue.has_ready():
                    return
                name = self.queue.pop().name
            else:
                name = next((n for n in self.order if n not in self.pending and n not in self.done
                             and self.graph[n] <= self.done), "")
                if not name:
                    return
            self.pending[name] = list(self.jobs[name])
            for job in self.jobs[name]:
                job.ready_at = self.now

    def _ready_jobs(self) -> list[Job]:
        ready = [j for name, pending in self.pending.items() for j in pending
                 if j not in self.started and not any(a in pending for a in j.after)]
        if self.policy == "chain first":
            return sorted(ready, key=lambda j: (-self.chain[j], self.rank[j]))
        return sorted(ready, key=lambda j: (j.ready_at, self.rank[j]))

    def _allowed(self, job: Job) -> bool:
        if self.policy == "chain first":
            return len(self.running) < self.cores
        mine = sum(1 for j in self.running if j.package == job.package and j.in_make)
        if not job.in_make or mine == 0:  # configure and install run outside make; a make's own slot
            return True
        if self.policy == "roc":
            tokens = sum(max(0, sum(1 for j in self.running if j.package == p and j.in_make) - 1)
                         for p in self.pending)
            return tokens < self.cores - 1
        if self.policy == "colcon":
            return mine < self.cores
        return mine < self.cores and len(self.running) < self.cores

    def _finish(self, job: Job) -> None:
        pending = self.pending[job.package]
        pending.remove(job)
        for other in pending:
            if job in other.after:
                other.ready_at = self.now
        if not pending:
            del self.pending[job.package]
            self.done.add(job.package)
            self.queue.done(job.package)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cores", default="2,4,8,16,32,64", help="core counts to replay")
    parser.add_argument("--retrace", action="store_true", help="trace the stack's build again")
    args = parser.parse_args(argv)
    if args.retrace or not JOBS_LOG.exists():
        if TRACE.exists():
            shutil.rmtree(TRACE)
        trace()
    graph, jobs, weights = load_trace()
    work = sum(j.work for js in jobs.values() for j in js)
    chain = max(chains_to_end(graph, jobs).values())
    print(f"the stack: {len(graph)} packages, {sum(len(j) for j in jobs.values())} jobs, {work:.0f} s of work "
          f"one at a time, its longest chain of jobs {chain:.0f} s")
    print(f"{'cores':>5} {'roc':>8} {'colcon':>8} {'colcon -l':>10} {'chain 1st':>10} {'bound':>7} "
          f"{'roc/colcon':>11} {'roc/colcon -l':>14} {'bound/colcon':>13}")
    for cores in (int(c) for c in args.cores.split(",")):
        roc, colcon, limited, first = (Replay(graph, jobs, weights, cores, p).run() for p in POLICIES)
        bound = lower_bound(graph, jobs, cores)
        print(f"{cores:>5} {roc:>7.1f}s {colcon:>7.1f}s {limited:>9.1f}s {first:>9.1f}s {bound:>6.1f}s "
              f"{roc / colcon:>10.2f}x {roc / limited:>13.2f}x {bound / colcon:>12.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
