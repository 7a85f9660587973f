"""The 3D butterfly in free flight: a free body moved only by the air, gravity and its own joints, steered by
its wing and abdomen kinematics.

Fly one::

    from lifelike_mj.butterfly import flight3d

    flight = flight3d.Flight3D(controller="monarch", task=flight3d.turn(90.0))
    flight.step(4000)                                # 5 s at the default time step, 1/800 s
    print(flight.state()["position_m"])              # x forward at the start, y left, z up (m)

A garden of butterflies visiting flowers::

    garden = flight3d.Garden(20, "designed", seed=1)
    garden.step(800)                                 # one second

Evolve a controller of your own (``lifelike-mj butterfly evolve3d`` does the same)::

    result, controller = flight3d.evolve(flight3d.TASK_SETS["steer"](), "mine.json", generations=50)

What is here, one layer on the next:

* :mod:`~lifelike_mj.butterfly.flight3d.animals`: the butterflies, the paper's swallowtail and the monarch with
  its measured wings (:data:`ANIMALS`, :func:`animal`); :mod:`~lifelike_mj.butterfly.flight3d.flowers`: flowers
  to land on (:func:`place_flowers`);
* :mod:`~lifelike_mj.butterfly.flight3d.kinematics`: the flap, feathering and abdomen kinematics
  (:class:`KinematicsCommand`, :class:`Kinematics`);
* :mod:`~lifelike_mj.butterfly.flight3d.model`: the MuJoCo model and its compiled air-force callback;
* :mod:`~lifelike_mj.butterfly.flight3d.tasks`: what a flight is asked to do (:class:`Task3D`, :func:`level`,
  :func:`turn`, :func:`course`, :func:`moving_target`, :func:`land`) and the compiled loop's array layouts;
* :mod:`~lifelike_mj.butterfly.flight3d.controllers`: the network's observation and action
  (:data:`OBS_NAMES`, :data:`ACTION_NAMES`), :class:`Controller3D` and its file (:func:`load_controller`);
* :mod:`~lifelike_mj.butterfly.flight3d.loop`: the compiled loop and the one owner of its state,
  :class:`Batch` (a flight is a batch of one, a garden a batch of n, an evolution candidates x tasks);
* :mod:`~lifelike_mj.butterfly.flight3d.flight`: the stepper :class:`Flight3D`;
* :mod:`~lifelike_mj.butterfly.flight3d.measures`: how natural a flight is (:func:`level_measures`);
  :mod:`~lifelike_mj.butterfly.flight3d.landing`: flowers visited by landing (:func:`visit_flowers`), a take-off
  measured (``take_off_measures``);
* :mod:`~lifelike_mj.butterfly.flight3d.garden`: :class:`Garden`, many butterflies among flowers;
* :mod:`~lifelike_mj.butterfly.flight3d.strobe`: stroboscopic pictures of one wing beat;
* :mod:`~lifelike_mj.butterfly.flight3d.evolution`: :class:`FlightProblem3D`, :data:`TASK_SETS`, :func:`evolve`;
* :mod:`~lifelike_mj.butterfly.flight3d.calibrate`: the calibrated wing law, fitted to a filmed monarch;
  :mod:`~lifelike_mj.butterfly.flight3d.averaged`: the butterfly averaged over its wing beat, trims, linear models and
  modes (:mod:`~lifelike_mj.butterfly.flight3d.controls`: its states, controls and natural envelope);
  :mod:`~lifelike_mj.butterfly.flight3d.designed`: a controller designed from them (shipped as ``designed``, the
  default; :func:`load_compiled` reads a controller of either kind ready to fly);
  :mod:`~lifelike_mj.butterfly.flight3d.predictive`: :class:`Planner`, predictive sampling on top of it, for courses
  in gusts;
* :mod:`~lifelike_mj.butterfly.flight3d.parts`: :class:`Butterfly` and :class:`World`, what a :class:`Flight3D` is
  made of besides its controller and task;
* :mod:`~lifelike_mj.butterfly.flight3d.validate`: the checks of a controller (level, turn, course, the
  reduction to the planar model); :mod:`~lifelike_mj.butterfly.flight3d.figures`: their figures.
"""

from lifelike_mj._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "KinematicsCommand": "kinematics", "Kinematics": "kinematics", "JOINTS": "kinematics",
    "build_model": "model",
    "Task3D": "tasks", "level": "tasks", "turn": "tasks", "course": "tasks", "moving_target": "tasks",
    "DRYDEN_VERTICAL_RATIO": "tasks", "new_record": "tasks",
    "Controller3D": "controllers", "load_controller": "controllers", "controller_from_dict": "controllers",
    "withdrawn_file": "controllers", "WITHDRAWN": "controllers",
    "OBS_NAMES": "controllers", "ACTION_NAMES": "controllers", "N_OBS": "controllers", "N_ACT": "controllers",
    "n_weights": "controllers",
    "Batch": "loop", "TUMBLE_RAD": "loop",
    "Flight3D": "flight", "DT_S": "timing", "DT_FINE_S": "timing", "STATE_UNITS": "flight", "euler_from_quat": "flight",
    "Garden": "garden",
    "FlightProblem3D": "evolution", "TASK_SETS": "evolution", "evolve": "evolution", "pd_prior": "evolution",
    "kinematics": ".", "model": ".", "tasks": ".", "controllers": ".", "loop": ".", "flight": ".", "garden": ".",
    "evolution": ".", "validate": ".", "figures": ".", "timing": ".", "view": ".", "view_flight3d": "view",
    "animals": ".", "measures": ".", "Animal": "animals", "ANIMALS": "animals", "animal": "animals",
    "level_measures": "measures", "default_base": "controllers", "strobe": ".",
    "flowers": ".", "landing": ".", "land": "tasks", "visit_flowers": "landing", "place_flowers": "flowers",
    "calibrate": ".", "averaged": ".", "controls": ".", "designed": ".", "designed_kernel": ".",
    "load_compiled": "designed_kernel", "perching": ".", "perch_layout": ".", "design_landing": "perching",
    "predictive": ".", "Planner": "predictive",
    "parts": ".", "Butterfly": "parts",
    "World": "parts",
}, globals())
