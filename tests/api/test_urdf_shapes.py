"""A URDF robot drawn with its links' shapes (issue 41): spacar.from_urdf reads the <visual> and
<collision> geometries, spacar.view3d draws them as surfaces on the links' frames at the state
drawn — placed where Pinocchio's forward kinematics puts the links of the same file; boxes,
cylinders and spheres triangulated, meshes read by trimesh (an STL here), a visual that cannot be
read replaced by the link's collision shape; the UR5 of example-robot-data drawn link by link."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import spacar
from spacar.geometry import frame_coordinates
from spacar.urdf import rpy_matrix

go = pytest.importorskip("plotly.graph_objects")

TETRA = """solid t
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0 1 0
  vertex 1 0 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 0 1
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0 1
  vertex 0 1 0
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 1 0 0
  vertex 0 1 0
  vertex 0 0 1
 endloop
endfacet
endsolid t
"""

INERTIA = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'


def arm(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "tetra.stl").write_text(TETRA)
    path = tmp_path / "arm.urdf"
    path.write_text(f"""<robot name="arm">
      <link name="base">
        <visual><geometry><mesh filename="package://arm_pkg/meshes/missing.dae"/></geometry></visual>
        <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
      </link>
      <link name="upper">{INERTIA}
        <visual><origin xyz="0.2 0 0" rpy="0 0 0.3"/><geometry><box size="0.4 0.05 0.06"/></geometry></visual>
      </link>
      <link name="fore">{INERTIA}
        <visual><origin xyz="0.15 0 0" rpy="0 1.5707963267948966 0"/>
          <geometry><cylinder radius="0.02" length="0.3"/></geometry></visual>
        <visual><origin xyz="0.3 0 0"/><geometry><sphere radius="0.03"/></geometry></visual>
        <visual><origin xyz="0.1 0.05 0" rpy="0.2 0 0"/>
          <geometry><mesh filename="meshes/tetra.stl" scale="0.1 0.1 0.1"/></geometry></visual>
      </link>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
        <origin xyz="0 0 0.3" rpy="0 0 0.5"/><axis xyz="0 0 1"/>
        <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
      <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
        <origin xyz="0.4 0 0.05" rpy="0.3 0.2 -0.1"/><axis xyz="0 0.6 0.8"/>
        <limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
    </robot>""")
    return path


def run(path, t_end=0.4):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = spacar.from_urdf(path, gravity=(0.0, -9.81, 0.0))
    model.timestep(4, t_end)
    return spacar.simulate(model, progress=False)


def placement(path, q, link):
    """(R, p) of the link's frame by Pinocchio's forward kinematics, else by the joints' own chain."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(q))
    frame = data.oMf[model.getFrameId(link)]
    return np.array(frame.rotation), np.array(frame.translation)


def surface(fig, link):
    return [np.column_stack([t.x, t.y, t.z]) for t in fig.data if t.type == "mesh3d" and t.name == f"link {link}"]


def test_the_shapes_sit_on_the_links_where_pinocchio_puts_them(tmp_path):
    pytest.importorskip("trimesh")
    path = arm(tmp_path)
    res = run(path)
    assert np.abs(res.q[-1]).max() > 0.05              # the arm has moved under gravity
    fig = spacar.view3d(res)
    # The upper arm's box: its corners at p + R (R_v c + xyz_v), c = (±0.2, ±0.025, ±0.03).
    R, p = placement(path, res.q[-1], "upper")
    corners = np.array([[sx * 0.2, sy * 0.025, sz * 0.03] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    expected = (corners @ rpy_matrix((0, 0, 0.3)).T + [0.2, 0, 0]) @ R.T + p
    (box,) = surface(fig, "upper")
    assert box == pytest.approx(expected, abs=1e-9)
    # The forearm: a cylinder along its x from 0 to 0.3, a sphere at 0.3, the STL tetrahedron.
    R, p = placement(path, res.q[-1], "fore")
    cylinder, sphere, tetra = surface(fig, "fore")
    along = (cylinder - p) @ R                          # in the link's frame
    assert along[:, 0].min() == pytest.approx(0.0, abs=1e-9) and along[:, 0].max() == pytest.approx(0.3, abs=1e-9)
    assert np.hypot(along[:, 1], along[:, 2]).max() == pytest.approx(0.02, abs=1e-9)
    assert np.linalg.norm(sphere - (p + R @ [0.3, 0, 0]), axis=1) == pytest.approx(0.03, abs=1e-9)
    local = np.array([[0, 0, 0], [0, 1, 0], [1, 0, 0], [0, 0, 1]]) * 0.1 @ rpy_matrix((0.2, 0, 0)).T + [0.1, 0.05, 0]
    assert sorted(map(tuple, np.round(tetra, 12))) == sorted(map(tuple, np.round(local @ R.T + p, 12)))
    # The base: its visual (a .dae that does not exist) replaced by the collision box.
    (base,) = surface(fig, "base")
    assert base[:, 2].min() == pytest.approx(0.0, abs=1e-12) and base[:, 2].max() == pytest.approx(0.1, abs=1e-12)


def test_without_a_mesh_reader_the_mesh_is_left_out_with_a_warning(tmp_path, monkeypatch):
    import builtins

    from spacar import visuals

    real_import = builtins.__import__

    def no_trimesh(name, *args, **kwargs):
        if name == "trimesh":
            raise ImportError("no trimesh")
        return real_import(name, *args, **kwargs)
    visuals._mesh.cache_clear()
    monkeypatch.setattr(builtins, "__import__", no_trimesh)
    path = tmp_path / "one.urdf"
    (tmp_path / "m.stl").write_text(TETRA)
    path.write_text(f"""<robot name="one"><link name="a"/><link name="b">{INERTIA}
      <visual><geometry><mesh filename="m.stl"/></geometry></visual></link>
      <joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/></joint></robot>""")
    res = run(path, 0.1)
    with pytest.warns(UserWarning, match=r"link 'b': its mesh .*m.stl: cannot be read \(pip install trimesh.*not drawn"):
        fig = spacar.view3d(res)
    assert not surface(fig, "b")
    assert not surface(spacar.view3d(res, links=False), "b")
    with pytest.raises(spacar.InputError, match="links must be True or False"):
        spacar.view3d(res, links="no")
    visuals._mesh.cache_clear()


def test_the_ur5_is_drawn_link_by_link():
    pytest.importorskip("trimesh")
    import importlib.metadata

    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    path = dist.locate_file("cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf")
    res = run(str(path), 0.1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fig = spacar.view3d(res)
    # COLLADA visuals need pycollada: without it each such link is drawn with its STL collision mesh
    # (the end-effector link has a collision box only: drawn with it).
    assert all("drawn with its collision shapes" in str(w.message) for w in caught)
    names = [t.name for t in fig.data if t.type == "mesh3d"]
    assert names == [f"link {n}" for n in ("base_link", "shoulder_link", "upper_arm_link", "forearm_link",
                                             "wrist_1_link", "wrist_2_link", "wrist_3_link", "ee_link")]
    # Each mesh on its link: the forearm's vertices near the forearm's frame (within its length).
    coords = frame_coordinates(res.node_columns, res.x[-1])
    fore = next(V for link, _, V, _ in res.shapes.surfaces(coords) if link == "forearm_link")
    origin = coords[res.shapes.frames["forearm_link"][0]]
    assert np.linalg.norm(fore - origin, axis=1).max() < 0.5
    assert math.isfinite(float(np.abs(fore).max()))


def test_package_names_with_three_slashes_and_missing_files(tmp_path):
    # package:///PKG/... (Talos's) is the package PKG; a file that is not there is named as such.
    from spacar.visuals import resolve

    pkg = tmp_path / "my_robot"
    (pkg / "urdf").mkdir(parents=True)
    urdf = pkg / "urdf" / "r.urdf"
    assert resolve("package:///my_robot/meshes/a.stl", str(urdf)) == str(pkg / "meshes" / "a.stl")
    assert resolve("package://my_robot/meshes/a.stl", str(urdf)) == str(pkg / "meshes" / "a.stl")
    urdf.write_text(f"""<robot name="r"><link name="a"/><link name="b">{INERTIA}
      <visual><geometry><mesh filename="package://my_robot/meshes/gone.stl"/></geometry></visual>
      <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
      <joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/></joint></robot>""")
    res = run(urdf, 0.1)
    with pytest.warns(UserWarning, match=r"gone.stl: no such file.*the rest of the link is drawn"):
        fig = spacar.view3d(res)
    assert len(surface(fig, "b")) == 1
    bad = tmp_path / "bad.urdf"
    bad.write_text("""<robot name="r"><link name="a"><visual><geometry><box size="0.1 -1 0.1"/></geometry></visual></link></robot>""")
    with pytest.raises(spacar.InputError, match="a box of negative size"):
        spacar.from_urdf(bad)
