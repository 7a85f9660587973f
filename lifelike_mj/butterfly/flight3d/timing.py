"""The 3D flight's time steps (importing this loads neither MuJoCo nor numba: the command line reads them to build its
help)."""

#: The 3D flight's time step (s): 80 steps per 10 Hz wing beat, the largest that keeps an open-loop flight within
#: 1 mm per second of its converged path (RK4) and the shipped controllers' scores within the spread of their own
#: flutter (``benchmarks/timestep_3d.py``; ``docs/performance.md``).
DT_S = 1.0 / 800.0
#: The step the shipped controllers were evolved at (1/1200 s), and the 3D flight's default before 0.3: still
#: selectable (``dt_s``, ``--dt 1/1200``); exports keep it by default.
DT_FINE_S = 1.0 / 1200.0
