"""One module per tool, each modelling every mechanism of ``mechanisms.ALL`` from the drawing
``common.load_drawing`` reads out of its model file.

Every module has ``TOOL`` (display name), ``PACKAGE`` (the PyPI name), ``version()`` (raises
ImportError when the tool is not installed), ``variants(benchmark) -> list[common.Variant]`` (its
methods, each with the integer setting ``cheapest.py`` searches: steps or a tolerance index),
``run(benchmark, drawing, variant, setting, reference) -> common.Run`` (the accuracy of one
setting against a ``common.Reference`` at the times the tool samples, raising or returning a failed Run
when the tool cannot run it: bench.py reports either with the reason) and ``timed(benchmark, drawing, variant, setting)``, the call ``timing.py`` times. Pinocchio
also has ``clocked(...)``: the same call, returning the seconds spent in its C++ dynamics.
"""
