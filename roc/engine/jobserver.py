"""A GNU make jobserver shared by every package build: one global budget of compiler jobs.

The pipe holds ``jobs - 1`` tokens and each make that joins holds one implicit slot (make's own
convention), so a package building alone can use the whole budget, and at most ``jobs + workers - 1``
compilers run at once, instead of colcon's workers x jobs.
"""

from __future__ import annotations

import os
import re

_J_FLAG = re.compile(r"(?:^|\s)(?:-j\s*(\d*)|--jobs(?:=(\d+))?)(?=\s|$)")


def jobs_from_makeflags(makeflags: str) -> int | None:
    """The -jN of a MAKEFLAGS value, if it has one."""
    for match in _J_FLAG.finditer(makeflags):
        value = match.group(1) or match.group(2)
        if value:
            return int(value)
    return None


class Jobserver:
    def __init__(self, jobs: int):
        self.jobs = jobs
        self.read_fd, self.write_fd = os.pipe()
        tokens = max(0, jobs - 1)
        if tokens:
            os.write(self.write_fd, b"+" * tokens)

    def makeflags(self, inherited: str) -> str:
        """MAKEFLAGS for a make that joins this jobserver (other inherited flags kept, -j replaced)."""
        kept = _J_FLAG.sub(" ", inherited)
        kept = re.sub(r"--jobserver-(?:auth|fds)=\S+", " ", kept).strip()
        return " ".join(p for p in (kept, f"-j{self.jobs}", f"--jobserver-auth={self.read_fd},{self.write_fd}") if p)

    @property
    def fds(self) -> tuple[int, int]:
        return self.read_fd, self.write_fd

    def close(self) -> None:
        for fd in self.fds:
            try:
                os.close(fd)
            except OSError:
                pass
