"""Matching features: one to one, and the paper's quality q (:mod:`~pcmapq.match.one_to_one`,
every detector); rooms by overlap, with what became of each unmatched one
(:mod:`~pcmapq.match.rooms`)."""

from __future__ import annotations

from pcmapq.match.one_to_one import Matching, assign, harmonic_mean, match

__all__ = ["Matching", "assign", "harmonic_mean", "match"]
