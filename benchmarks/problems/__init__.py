"""The verification problems of `make verify`, one module a problem; the CLI that runs
them under mpirun is ``benchmarks/verify_case.py``.

Every reference comes from closed-form continuum mechanics or from an integration
written in these modules; none calls the solver's own formulas.

Each problem is a class with ``RESOLUTIONS``, ``QUICK`` and ``run(team, res)``:

==============  ====================  ==============================================
key             module                problem
==============  ====================  ==============================================
``wave``        :mod:`.wave`          plane P wave in granite, 1-D strain
``lame``        :mod:`.lame`          thick elastic cylinder under internal pressure
``energy``      :mod:`.energy`        free elastic block: energy drift and deviation
``jh2_point``   :mod:`.jh2_point`     one JH2 point on a uniaxial-strain path
``detonation``  :mod:`.detonation`    explosive column in a copper tube
``isentrope_dt`` :mod:`.detonation`   the same at one dx with dt refined alone
``wave_multirate`` :mod:`.wave_multirate` the plane wave across a multi-rate class boundary
``borehole_multirate`` :mod:`.borehole_multirate` a borehole pressure pulse across one
``kalthoff_winkler`` :mod:`.kalthoff_winkler` the crack angle at two notch tips (steel)
==============  ====================  ==============================================

:mod:`.common` holds what they share (the paper's granite, scene building, the
stable step, the slowest rank's wall time).

Two hooks reach past the scene file, both in this harness only: the wave's lateral
rollers (the solver has no per-component boundary condition) and the Lame
cylinder's global damping (the solver's damping acts on failed points only).
"""
from .borehole_multirate import BoreholeMultirate
from .detonation import Detonation, IsentropeDt
from .energy import Energy
from .jh2_point import JH2Point
from .kalthoff_winkler import KalthoffWinkler
from .lame import Lame
from .wave import Wave
from .wave_multirate import WaveMultirate

PROBLEMS = {"wave": Wave, "lame": Lame, "energy": Energy, "jh2_point": JH2Point,
            "detonation": Detonation, "isentrope_dt": IsentropeDt,
            "wave_multirate": WaveMultirate, "borehole_multirate": BoreholeMultirate,
            "kalthoff_winkler": KalthoffWinkler}
