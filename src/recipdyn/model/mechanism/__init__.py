"""The mechanism of a throw: crank, connecting rod and crosshead.

`.link` is the throw with the paper's massless link at the crank pin (``rc = 0``: an ideal
pin): its parameter slice, its states, its compiled functions by role (the clearance angle's
acceleration with a prescribed crank, its contribution to a free crank, the crosshead's
motion) and the signals a record draws from it. The assembler (`recipdyn.model.assembler`)
places one such throw per crank of a machine. Nothing here is imported at package import:
the declarations load without numba.
"""
