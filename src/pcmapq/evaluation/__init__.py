"""One evaluation, stage by stage: the inputs read as plans (:mod:`~pcmapq.evaluation.inputs`),
the truth prepared once (:mod:`~pcmapq.evaluation.prepared`), the map placed on it and the
same-place verdict (:mod:`~pcmapq.evaluation.placing`, :mod:`~pcmapq.evaluation.same_place`),
the whole run (:mod:`~pcmapq.evaluation.pipeline`), and the no-reference figures
(:mod:`~pcmapq.evaluation.noref_figures`, :mod:`~pcmapq.evaluation.inspect_map`)."""
