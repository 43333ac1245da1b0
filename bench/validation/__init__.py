"""The validation of pcmapq on the real maps of ../shared/data: docs/validation.md, every figure
measured when it is generated, and a stored reference of every case it runs.

    python -m bench.validation [--only SECTION] [--data DIR] [--check] [--write]
        [--save-references]

One module per section of the document (:mod:`bench.validation.document` lists them in order),
each with ``cases(data)``, the runs whose figures have a reference in
``tests/reference/validation/``, and ``section(data, record)``, its markdown measured then.
"""
