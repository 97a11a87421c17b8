"""One module per tool, each modelling every mechanism of ``mechanisms.ALL`` from the drawing
``common.load_drawing`` reads out of its model file.

Every module has ``TOOL`` (display name), ``PACKAGE`` (the PyPI name), ``version()``
(raises ImportError when the tool is not installed), ``SWEEPS`` (per mechanism key, the
settings of its work-precision curve; a mechanism without one is reported as not modelled)
and ``run(benchmark, drawing, setting, ref_grid) -> common.Run`` (raising, or returning a
failed Run, when the tool cannot model or run it: bench.py reports either with the reason).
"""
