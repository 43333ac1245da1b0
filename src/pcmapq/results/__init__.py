"""What an evaluation produces and how it is read: the :class:`~pcmapq.results.result.Result`,
its figures by name, CI gates on them, and the comparison of saved results."""
