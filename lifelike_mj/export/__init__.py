"""The motion leaving the project: a run's body poses (:func:`~lifelike_mj.export.poses.record_poses`) written
as animated glTF 2.0 (:func:`~lifelike_mj.export.gltf.write_gltf`) for Blender, game engines and the web.

Works on any simulation in the stepper shape (:class:`lifelike_mj.stepper.Stepper`): it reads only
``model``, ``data``, ``step``, ``sync`` and ``dt``.
"""
