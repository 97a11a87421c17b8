"""One module per tool, each modelling the four-bar of ``common.load_four_bar`` exactly.

Every module has ``TOOL`` (display name), ``PACKAGE`` (the PyPI name), ``version()``
(raises ImportError when the tool is not installed), ``SWEEP`` (the settings of its
work-precision curve) and ``run(fb, setting, ref_grid) -> common.Run``.
"""
