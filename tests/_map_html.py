"""Reading back the scene an ``antenna map`` view (map.html) embeds."""

from __future__ import annotations

import base64
import io
import re
from pathlib import Path

import trimesh


def html_scene(path: Path) -> trimesh.Scene:
    """The glTF scene embedded in ``path`` (base64 in the page's script), loaded by trimesh."""
    found = re.findall(r'"([A-Za-z0-9+/=]{200,})"', path.read_text())
    assert len(found) == 1, "expected one embedded base64 glTF"
    scene = trimesh.load(io.BytesIO(base64.b64decode(found[0])), file_type="glb")
    assert isinstance(scene, trimesh.Scene)
    return scene
