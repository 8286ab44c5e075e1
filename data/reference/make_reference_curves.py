"""Write the paper's closed-form reference curves (Figs. 5b, 6a–c) into data/reference/.

Usage: ``python data/reference/make_reference_curves.py``. The tables are computed by
:func:`passmd.reference.closed_form_curves` (Eqs. 1, 7–14 of Nguyen et al. 2018 via
``passmd.theory``) on ``passmd.parameters.PRELOAD_GRIDS``; ``tests/test_reference.py``
fails if the committed files and a fresh computation disagree.
"""

from passmd.reference import write_reference_curves

if __name__ == "__main__":
    for path in write_reference_curves():
        print("wrote", path)
