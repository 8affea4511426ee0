"""Scenes for the simulated device: objects as meshes at any pose, and sweeps that touch them.

Above ``simulator/`` (it calls ``simulate``) and ``mapping/`` (poses, shape classes), below
``exploration/`` and ``cli/`` (docs/explore.md):

- :mod:`.objects`: :class:`SceneObject`, a primitive or a user's mesh at a pose;
- :mod:`.file`: :class:`Scene` and its TOML file (:func:`load_scene`);
- :mod:`.sweep`: :class:`Sweep`, the link's sagged shape (:class:`LinkShape`) and the angles
  under which a base sees an object (:func:`facing_region`);
- :mod:`.touch`: :func:`first_touch`, where a sweep's link meets the scene;
- :mod:`.simulate`: :func:`simulate_sweep`, the touch run through the simulator's physics.
"""

from sensing_antenna.scene.file import BUILTIN_SCENES, ExploreRegion, Scene, SceneError, load_scene
from sensing_antenna.scene.objects import (
    OBJECT_SHAPES,
    SIZE_KEYS,
    SceneObject,
    mesh_object,
    primitive_object,
)
from sensing_antenna.scene.simulate import OUTCOMES, SweepOutcome, simulate_sweep, touch_scenario
from sensing_antenna.scene.sweep import LinkShape, Sweep, facing_region
from sensing_antenna.scene.touch import SweepGeometry, Touch, first_touch

__all__ = [
    "BUILTIN_SCENES",
    "OBJECT_SHAPES",
    "OUTCOMES",
    "SIZE_KEYS",
    "ExploreRegion",
    "LinkShape",
    "Scene",
    "SceneError",
    "SceneObject",
    "Sweep",
    "SweepGeometry",
    "SweepOutcome",
    "Touch",
    "facing_region",
    "first_touch",
    "load_scene",
    "mesh_object",
    "primitive_object",
    "simulate_sweep",
    "touch_scenario",
]
