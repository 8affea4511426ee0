"""``antenna map`` end to end on simulated recordings, scored against their ground truth."""

from __future__ import annotations

import csv
import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from _map_html import html_scene
from _models import calibrated
from sensing_antenna.antenna import save_antenna
from sensing_antenna.cli import main
from sensing_antenna.cli.map import read_objects
from sensing_antenna.mapping import (
    BasePose,
    map_inputs_from_recordings,
    points_from_recordings,
    swept_from_recordings,
)
from sensing_antenna.mapping.points import TANGENT_FLOOR
from sensing_antenna.recording import read_recording, write_recording

#: A base pose for the third recording: turned 30 degrees about Z and lifted onto a robot.
POSE = BasePose.from_quaternion(
    [0.2, -0.1, 0.4], [math.cos(math.pi / 12), 0.0, 0.0, math.sin(math.pi / 12)]
)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    folder = tmp_path_factory.mktemp("map")
    paths = [folder / "post.csv", folder / "bar.csv", folder / "moved.csv"]
    for path, case, x_c in ((paths[0], "azimuthal", "0.5"), (paths[1], "vertical", "0.6")):
        assert main(["simulate", "--case", case, "--xc", x_c, "--out", str(path)]) == 0
    moved = read_recording(paths[0]).with_metadata(base_pose=POSE.to_json())
    write_recording(moved, paths[2])
    return paths


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open() as handle:
        return list(csv.DictReader(handle))


def test_map_writes_points_within_their_covariance_of_the_truth(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, model = tmp_path / "map", tmp_path / "model.toml"
    save_antenna(calibrated(), model)  # a calibrated antenna: the datasheet's would be uncertain
    assert main(["map", *map(str, recordings), "--out", str(out), "--antenna", str(model)]) == 0
    assert "3 of 3 points used" in capsys.readouterr().out
    for name in ("points.csv", "points.ply", "recognition.json", "report.md", "map.png"):
        assert (out / name).stat().st_size > 0
    rows = _rows(out / "points.csv")
    assert [row["status"] for row in rows] == ["ok", "ok", "ok"]
    points = []
    for row in rows:
        point = np.array([float(row[k]) for k in ("x", "y", "z")])
        truth = np.array([float(row[k]) for k in ("true_x", "true_y", "true_z")])
        c = {k: float(row[f"cov_{k}"]) for k in ("xx", "xy", "xz", "yy", "yz", "zz")}
        covariance = np.array(
            [[c["xx"], c["xy"], c["xz"]], [c["xy"], c["yy"], c["yz"]], [c["xz"], c["yz"], c["zz"]]]
        )
        tangent = np.array([float(row[f"tangent_{k}"]) for k in "xyz"])
        # the link's tangent at the contact: a unit vector, with its angular deviation
        assert np.linalg.norm(tangent) == pytest.approx(1.0, abs=1e-6)
        # at least the pointing floor; with the push's direction reported, rho = 10 % of its
        # slope (0.15 rad at a 10 % push) adds little, far below 0.1 rad
        assert TANGENT_FLOOR <= float(row["tangent_std"]) < 0.1
        error = point - truth
        # Mahalanobis distance of the truth: below 3.37, the 99 % point of chi with 3 dof
        assert float(np.sqrt(error @ np.linalg.solve(covariance, error))) < 3.37, row["source"]
        points.append((point, truth, covariance))
    # the moved recording is the first one, placed by its base pose: point, truth, covariance
    assert np.allclose(points[2][0], POSE.point_to_world(points[0][0]))
    assert np.allclose(points[2][1], POSE.point_to_world(points[0][1]))
    assert np.allclose(points[2][2], POSE.covariance_to_world(points[0][2]))
    tangents = [np.array([float(row[f"tangent_{k}"]) for k in "xyz"]) for row in rows]
    assert np.allclose(tangents[2], POSE.rotation @ tangents[0], atol=1e-6)
    # from the base (the origin here) towards the point, within the link's bend and sag
    assert tangents[0] @ points[0][0] / np.linalg.norm(points[0][0]) > 0.99
    summary = json.loads((out / "recognition.json").read_text())
    assert summary["n_used"] == 3 and summary["recognition"] is None  # too few to recognise
    # the interactive view holds the same points, self-contained (no script fetched)
    html = (out / "map.html").read_text()
    assert "<script src" not in html and 'src="http' not in html
    view = html_scene(out / "map.html")
    cloud = view.geometry["points"]
    assert np.allclose(np.sort(cloud.vertices, axis=0), np.sort([p[0] for p in points], axis=0))
    assert "truth" not in view.geometry  # antenna map knows no true surface


def test_a_map_into_a_previous_map_s_directory_leaves_none_of_its_files_behind(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a previous map named an object and drew a surface; this one, with the datasheet's
    # antenna, uses no point: a file of the old map beside the new report would contradict it
    out = tmp_path / "map"
    out.mkdir()
    earlier = ["points.ply", "surface.ply", "object.ply", "map.html"]
    for name in earlier:
        (out / name).write_text("a previous map's\n")
    (out / "recognition.json").write_text(json.dumps({"files": earlier}))
    assert main(["map", *map(str, recordings), "--out", str(out), "--no-progress"]) == 0
    assert "0 of 3 points used" in capsys.readouterr().out
    assert sorted(p.name for p in out.iterdir()) == [
        "map.png",
        "points.csv",
        "recognition.json",
        "report.md",
    ]
    assert json.loads((out / "recognition.json").read_text())["files"] == [
        "map.png",
        "points.csv",
        "recognition.json",
        "report.md",
    ]
    # a directory of the user's own: their files are theirs, mapped into once or twice
    own = tmp_path / "scans"
    own.mkdir()
    (own / "object.ply").write_text("a scan of the object\n")
    for _ in range(2):
        assert main(["map", *map(str, recordings), "--out", str(own), "--no-progress"]) == 0
        assert (own / "object.ply").read_text() == "a scan of the object\n"


@pytest.mark.parametrize(
    ("problem", "words"),
    [
        ("missing", "absent.csv: cannot read file"),
        ("pose", "base_pose: not JSON"),
        ("mesh", "junk.stl: "),
        # a mesh in mm read as metres: the message names the option that reads it
        ("mesh in mm", "a thousand times too large; read in m; give the file's unit with"),
        ("out is a file", "out: File exists (a file where a directory is to be made?)"),
    ],
)
def test_bad_input_is_one_line_exit_2(
    problem: str,
    words: str,
    recordings: list[Path],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    argv = ["map", str(recordings[0]), "--out", str(tmp_path / "out"), "--no-progress"]
    if problem == "missing":
        argv[1] = str(tmp_path / "absent.csv")
    elif problem == "pose":
        bad = tmp_path / "bad.csv"
        write_recording(read_recording(recordings[0]).with_metadata(base_pose="{"), bad)
        argv[1] = str(bad)
    elif problem == "out is a file":
        (tmp_path / "out").write_text("")
    elif problem == "mesh":
        mesh = tmp_path / "junk.stl"
        mesh.write_text("solid nothing here\nthis is not an stl\n")
        argv += ["--objects", str(mesh)]
    else:
        box = trimesh.creation.box(extents=[0.06, 0.1, 0.14])
        box.apply_scale(1000.0)
        mesh = tmp_path / "box_mm.stl"
        box.export(mesh)
        argv += ["--objects", str(mesh)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("antenna map: error: ") and words in err, err
    assert "\n" not in err


def test_an_open_mesh_is_registered_with_a_warning(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a box without its lid (a scan open where it stood): registered, but points on the missing
    # face count against it, which the user is told
    box = trimesh.creation.box(extents=[0.06, 0.1, 0.14])
    lid = box.face_normals[:, 2] > 0.5
    mesh = tmp_path / "open.stl"
    trimesh.Trimesh(box.vertices, box.faces[~lid]).export(mesh)
    argv = ["map", str(recordings[0]), "--out", str(tmp_path / "out"), "--no-progress"]
    assert main([*argv, "--objects", str(mesh)]) == 0
    err = capsys.readouterr().err
    assert f"antenna map: warning: {mesh}: the mesh is not closed (watertight): points on" in err


def test_a_mesh_in_millimetres_is_read_with_its_unit(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    box = trimesh.creation.box(extents=[0.06, 0.1, 0.14])
    box.apply_scale(1000.0)  # a CAD export: 60 x 100 x 140 mm
    mesh = tmp_path / "box_mm.stl"
    box.export(mesh)
    read = read_objects([mesh], "antenna map", "mm")["box_mm"]
    assert np.allclose(sorted(read.extents), [0.06, 0.1, 0.14], rtol=1e-9)
    argv = ["map", str(recordings[0]), "--out", str(tmp_path / "out"), "--no-progress"]
    assert main([*argv, "--objects", str(mesh), "--objects-unit", "mm"]) == 0
    assert capsys.readouterr().err == ""
    # a file in metres read as millimetres: the message names the unit it was read in
    metres = tmp_path / "box_m.stl"
    trimesh.creation.box(extents=[0.06, 0.1, 0.14]).export(metres)
    assert main([*argv, "--objects", str(metres), "--objects-unit", "mm"]) == 2
    err = capsys.readouterr().err
    assert "read in mm; give the file's unit with --objects-unit m|cm|mm|in" in err


def test_a_bad_recording_among_good_ones_is_left_out_in_one_line(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a lab's set with one truncated or missing file: the map is made of the others, and the
    # file left out is named in a line of its own after the bar, which counts every file
    bad = tmp_path / "bad.csv"
    write_recording(read_recording(recordings[0]).with_metadata(base_pose="{"), bad)
    argv = ["map", str(recordings[0]), str(tmp_path / "absent.csv"), str(bad), str(recordings[1])]
    assert main([*argv, "--out", str(tmp_path / "out")]) == 0
    captured = capsys.readouterr()
    assert " of 2 points used" in captured.out
    lines = captured.err.strip().splitlines()
    warnings = [line for line in lines if line.startswith("antenna map: warning: left out ")]
    assert len(warnings) == 2, lines
    assert "absent.csv: cannot read file" in warnings[0]
    assert "bad.csv: base_pose: not JSON" in warnings[1]
    assert any("4/4" in line for line in lines if line.startswith("estimating")), lines
    rows = _rows(tmp_path / "out" / "points.csv")
    assert [Path(row["source"]).name for row in rows] == ["post.csv", "bar.csv"]


def test_one_pass_over_the_recordings_gives_what_two_do(recordings: list[Path]) -> None:
    antenna = calibrated()
    done: list[Path] = []
    points, (free, touched) = map_inputs_from_recordings(recordings, antenna, progress=done.append)
    assert done == recordings
    apart = points_from_recordings(recordings, antenna)
    assert [p.point.tolist() for p in points] == [p.point.tolist() for p in apart]
    assert [p.status for p in points] == [p.status for p in apart]
    free_apart, touched_apart = swept_from_recordings(recordings, antenna, apart)
    for one, two in ((free, free_apart), (touched, touched_apart)):
        assert one.n_sweeps == two.n_sweeps
        np.testing.assert_array_equal(one.samples, two.samples)


def test_recordings_of_another_antenna_mapped_with_the_default_are_warned_of(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A lab's recordings name their antenna's file; mapped without it, every estimate uses the
    # default's observer and stiffness, which can look like bad data: one warning line per
    # antenna named, kept in report.md, none when the antenna is given
    lab = [tmp_path / f"lab-{i}.csv" for i in range(2)]
    for source, path in zip(recordings, lab, strict=False):
        write_recording(read_recording(source).with_metadata(antenna="lab-antenna"), path)
    paths = [*map(str, lab), str(recordings[2])]
    model = tmp_path / "model.toml"
    save_antenna(calibrated(), model)
    assert main(["map", *paths, "--out", str(tmp_path / "a"), "--no-progress"]) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warnings) == 1
    assert "2 recording(s)" in warnings[0] and "'lab-antenna'" in warnings[0]
    assert f"{lab[0]} and 1 more" in warnings[0] and "--antenna" in warnings[0]
    report = (tmp_path / "a" / "report.md").read_text()
    assert f"- {warnings[0].removeprefix('antenna map: ')}\n" in report
    args = ["map", *paths, "--out", str(tmp_path / "b"), "--antenna", str(model), "--no-progress"]
    assert main(args) == 0
    assert "warning" not in capsys.readouterr().err


def test_a_sample_period_its_stamps_contradict_is_warned_of_and_kept_in_the_report(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # metadata saying 2 ms over stamps 1 ms apart: estimated by the stamps, the file named
    wrong = tmp_path / "wrong-period.csv"
    write_recording(read_recording(recordings[0]).with_metadata(sample_period="0.002"), wrong)
    assert main(["map", str(wrong), str(recordings[1]), "--out", str(tmp_path / "a")]) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warnings) == 1 and warnings[0].startswith(f"antenna map: warning: {wrong}: ")
    assert "sample_period" in warnings[0]
    report = (tmp_path / "a" / "report.md").read_text()
    assert f"- {warnings[0].removeprefix('antenna map: ')}\n" in report


def test_a_map_that_fails_leaves_no_directory_it_made(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "new" / "map"
    argv = ["map", str(tmp_path / "absent.csv"), "--out", str(out), "--no-progress"]
    assert main(argv) == 2
    assert not out.parent.exists()
    # a directory that was there before stays, with what it held
    out.mkdir(parents=True)
    (out / "notes.txt").write_text("mine")
    assert main(argv) == 2
    assert (out / "notes.txt").read_text() == "mine"
    capsys.readouterr()


def test_recordings_without_a_base_pose_among_posed_ones_are_noted(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # two recordings at the world's origin and one moved: consistent when the unposed ones were
    # made there, so a note that says what was assumed, not a warning
    args = ["--out", str(tmp_path / "a"), "--no-progress"]
    assert main(["map", *map(str, recordings), *args]) == 0
    notes = [line for line in capsys.readouterr().err.splitlines() if "base_pose" in line]
    assert notes == [
        f"antenna map: note: 2 of 3 recordings have no base_pose ({recordings[0]} and 1 more): "
        "their points are placed with the antenna's base at the world's origin, unturned "
        "(docs/recording-format.md)"
    ]
    # none posed, or all: nothing to say
    assert main(["map", str(recordings[0]), str(recordings[1]), *args]) == 0
    assert "base_pose" not in capsys.readouterr().err
    assert main(["map", str(recordings[2]), *args]) == 0
    assert "base_pose" not in capsys.readouterr().err


def test_a_map_where_no_recording_shows_a_contact_says_which_antenna_may_be_wrong(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # an antenna whose threshold lies far above these touches' residual misses them all, as
    # another device's file would: the map says what to check, not only "no_contact 3"
    deaf = calibrated()
    deaf = dataclasses.replace(
        deaf, observer=dataclasses.replace(deaf.observer, contact_threshold=50.0)
    )
    model = tmp_path / "deaf.toml"
    save_antenna(deaf, model)
    args = ["--out", str(tmp_path / "m"), "--antenna", str(model), "--no-progress"]
    assert main(["map", *map(str, recordings), *args]) == 0
    out = capsys.readouterr().out
    assert "no_contact 3" in out
    assert "no recording shows a contact" in out and "--antenna" in out
    # a map with a point used has nothing to say of it
    assert main(["map", *map(str, recordings), "--out", str(tmp_path / "n"), "--no-progress"]) == 0
    assert "no recording shows a contact" not in capsys.readouterr().out


def test_a_base_pose_key_written_otherwise_is_named(
    recordings: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # every file's key misspelled: no file has a base_pose, so the count says nothing, but
    # each key written otherwise is named, with the key the format reads
    posed = read_recording(recordings[2])
    pose = posed.metadata["base_pose"]
    metadata = {k: v for k, v in posed.metadata.items() if k != "base_pose"}
    typo = tmp_path / "typo.csv"
    write_recording(dataclasses.replace(posed, metadata={**metadata, "Base-Pos": pose}), typo)
    assert main(["map", str(typo), "--out", str(tmp_path / "a"), "--no-progress"]) == 0
    notes = [line for line in capsys.readouterr().err.splitlines() if "base_pose" in line]
    assert notes == [
        f"antenna map: note: {typo}: metadata key 'Base-Pos' is not read: 'base_pose'? (the "
        "point is placed with the base at the world's origin)"
    ]
    # what was said of the inputs stays with the map
    report = (tmp_path / "a" / "report.md").read_text()
    assert report.endswith(f"## The inputs\n\n- {notes[0].removeprefix('antenna map: ')}\n")
