"""From contact points to a surface and an object (docs/mapping.md).

Above ``estimation/`` (it turns estimates into world points), below ``cli/``:

- :mod:`.pose`: the antenna base's pose in the world (``base_pose`` metadata);
- :mod:`.points`: :class:`ContactPoint`, a touched point with its covariance;
- :mod:`.surface`: :class:`ImplicitSurface`, a Gaussian-process implicit surface;
- :mod:`.free_space`: :class:`FreeSpace` and :class:`Touches`, where the links swept without
  touching and where they touched;
- :mod:`.primitives`: the shape classes, their exact signed distances and meshes;
- :mod:`.recognition`: every class fitted to the points, the links' lines and the swept links,
  scored by BIC,
  a decision that abstains when a class the points do not rule out is another shape;
- :mod:`.contact_map`: :func:`build_map`, :func:`points_from_recordings`,
  :func:`swept_from_recordings` and :func:`map_inputs_from_recordings` (both, each recording
  read once);
- :mod:`.store`: the map's directory;
- :mod:`.view`: the interactive HTML view (map.html).
"""

from sensing_antenna.mapping.contact_map import (
    ContactMap,
    build_map,
    map_inputs_from_recordings,
    points_from_recordings,
    swept_from_recordings,
)
from sensing_antenna.mapping.free_space import FreeSpace, Touches, free_space, touches
from sensing_antenna.mapping.points import (
    ContactPoint,
    PointUncertainty,
    contact_point_from_estimate,
    select_points,
)
from sensing_antenna.mapping.pose import BasePose, base_pose_from_metadata
from sensing_antenna.mapping.primitives import PRIMITIVES, Primitive
from sensing_antenna.mapping.recognition import (
    ABSTAIN_DELTA,
    UNDECIDED,
    ClassFit,
    LinkLines,
    Recognition,
    fit_mesh,
    fit_primitive,
    recognise,
)
from sensing_antenna.mapping.store import write_map
from sensing_antenna.mapping.surface import ImplicitSurface

__all__ = [
    "ABSTAIN_DELTA",
    "PRIMITIVES",
    "UNDECIDED",
    "BasePose",
    "ClassFit",
    "ContactMap",
    "ContactPoint",
    "FreeSpace",
    "ImplicitSurface",
    "LinkLines",
    "PointUncertainty",
    "Primitive",
    "Recognition",
    "Touches",
    "base_pose_from_metadata",
    "build_map",
    "contact_point_from_estimate",
    "fit_mesh",
    "fit_primitive",
    "free_space",
    "map_inputs_from_recordings",
    "points_from_recordings",
    "recognise",
    "select_points",
    "swept_from_recordings",
    "touches",
    "write_map",
]
