"""One evaluation, stage by stage: the inputs read as plans (:mod:`~pcmapq.evaluation.inputs`),
the truth prepared once (:mod:`~pcmapq.evaluation.truth`), the map placed on it with the
same-place verdict (:mod:`~pcmapq.evaluation.placing`, :mod:`~pcmapq.evaluation.same_place`),
scored (:mod:`~pcmapq.evaluation.scoring`), the whole run (:mod:`~pcmapq.evaluation.pipeline`),
and the no-reference figures (:mod:`~pcmapq.evaluation.noref_figures`,
:mod:`~pcmapq.evaluation.inspect_map`)."""
