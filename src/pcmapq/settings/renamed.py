"""Former option names still read (:data:`RENAMED`): each option has one name on every command
(:mod:`pcmapq.settings.table`); a name it had before is still taken where it was, with one
warning naming the option now."""

from __future__ import annotations

from dataclasses import dataclass

from pcmapq.settings.table import INSPECT

__all__ = ["RENAMED", "Renamed", "renamed_of"]


@dataclass(frozen=True)
class Renamed:
    """An option's former name (``radius``), still read where it was taken: as a command's
    option (``--radius``, hidden from the help) or a batch manifest's column, with one warning
    naming the option now (``--noref-radius``). ``commands``: the commands that took it. A
    switch is not renamed this way."""

    old: str
    new: str
    commands: tuple[str, ...]

    @property
    def option(self) -> str:
        """The former option as typed: ``--radius``."""
        return "--" + self.old.replace("_", "-")


#: Every renamed option: inspect named its settings apart from eval's until each setting had
#: one name on every command (the setting's group and key: ``--noref-radius`` for
#: ``noref.radius``). The docs' option tables list them (:mod:`pcmapq.report.docs_tables`).
RENAMED: tuple[Renamed, ...] = (
    Renamed("crop", "map_crop", (INSPECT,)),
    Renamed("topic", "map_topic", (INSPECT,)),
    Renamed("radius", "noref_radius", (INSPECT,)),
    Renamed("voxel", "noref_voxel", (INSPECT,)),
    Renamed("sample", "noref_sample", (INSPECT,)),
    Renamed("min_knn", "noref_min_knn", (INSPECT,)),
    Renamed("max_nn", "noref_max_nn", (INSPECT,)),
)


def renamed_of(command: str) -> tuple[Renamed, ...]:
    """The former names ``command`` still reads."""
    return tuple(r for r in RENAMED if command in r.commands)
