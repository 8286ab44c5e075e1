"""passmd: reproducible replication of Nguyen et al. (2018), Coatings 8, 62.

"Improvements of Piezo-Actuated Stick–Slip Micro-Drives: Modeling and Driving
Waveform". The package follows the paper's structure:

``parameters``     Tables 1–2, the drive's parameter records and the assumptions
``theory``         closed forms: Hertz, Cattaneo–Mindlin, Eqs. 1 and 7–14
``contact``        MDR contact with memory (Eqs. 4–6): discrete springs and exact limit
``mdr_validation`` the MDR contact against Hertz, Cattaneo–Mindlin and Masing
``dynamics``       hybrid simulation of runner and actuators (Eqs. 2–3)
``waveforms``      saw-tooth and piecewise-linear piezo trajectories (``optimized_waveform``: Eq. 15)
``experiments``    one function per figure panel, returning tidy data (plots in ``plots``)
``reference``      the paper's closed-form reference curves (passmd/data/reference/, package data)
``ledger``         the paper's claims against our results
``sweep``          parameter grids in parallel (process pool or Dask), cached (``cache``)
``units``          quantities with units at the command line
``publish``        helpers of the book's chapters
``provenance``     version, git commit and profile stamped on figures and CSV files
``cli``            the ``passmd`` command line
"""

#: The version: its one source (pyproject.toml reads it, ``dynamic = ["version"]``; CITATION.cff
#: and CHANGELOG.md name it, and tests/test_packaging.py checks they agree).
__version__ = "0.1.0"

#: The replicated paper, as cited in the book and the command line's help.
PAPER_CITATION = (
    "X.-H. Nguyen, T.-H. Mau, I. Meyer, B.-L. Dang, H.-P. Pham, "
    "\"Improvements of Piezo-Actuated Stick–Slip Micro-Drives: Modeling and Driving "
    "Waveform\", Coatings 8(2), 62 (2018), doi:10.3390/coatings8020062"
)
