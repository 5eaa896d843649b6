"""Interactive exploration in a notebook (ipywidgets; matplotlib draws, the widget shows PNG
images, so it needs no ipympl and works headless) and an interactive 3-D view (plotly).

* :func:`explore` — sliders for an input motion of a model (e.g. the crank angle: the kinematics
  is solved again at each value, moving continuously from the assembled state so the mechanism
  stays on its branch) and for chosen model parameters (a node's X coordinate, which sets the
  reference geometry, or any function of the model), with the mechanism redrawn, the paths of
  chosen nodes over the input's range and a chosen quantity plotted against the input. Given
  :class:`spacar.Results` instead of a model, the slider runs through the output times.
* :func:`view3d` — the mechanism at one output time as a plotly figure that can be turned and
  zoomed in the notebook; without plotly, :func:`spacar.draw`'s matplotlib 3-D drawing.

(The module is not called ``explore``: importing it would then replace the function
``spacar.explore`` by the module.)
"""
from __future__ import annotations

import io
import math

import numpy as np

from ._util import show
from .errors import InputError, SpacarError
from .geometry import Geometry, shapes, frame_coordinates
from .results import _ARRAYS, STATE_ARRAYS, Results, parse_spec


def _widgets():
    try:
        import ipywidgets
    except ImportError:
        raise ImportError('spacar.explore needs ipywidgets: pip install ipywidgets (from a clone of spacar: '
                          'pip install ".[classroom]")') from None
    return ipywidgets


_BOX = None


def _static_fallback_box():
    """An ipywidgets VBox whose display also carries the picture it shows as a PNG: a live
    notebook shows the widget, a notebook exported to HTML (:func:`spacar.notebook.to_html`,
    which drops widget views that have a static fallback) the picture of its last state."""
    global _BOX
    if _BOX is None:
        widgets = _widgets()

        class Box(widgets.VBox):
            def _repr_mimebundle_(self, **kwargs):
                import base64

                bundle = super()._repr_mimebundle_(**kwargs) or {}
                explorer = getattr(self, "explorer", None)
                if explorer is not None and explorer.image.value:
                    bundle["image/png"] = base64.b64encode(explorer.image.value).decode("ascii")
                return bundle

        _BOX = Box
    return _BOX


class Explorer:
    """The state behind an :func:`explore` widget: ``widget`` (the ipywidgets box), ``scene``
    (the :class:`spacar.plotting.Scene` of the mechanism), ``figure``, ``sliders`` ({name:
    slider}), ``message`` (a Label: why a value could not be reached) and, for a model,
    ``state`` (one-row Results of the drawn state) and ``value`` (the input's value)."""

    def __init__(self, source, *, input=None, input_range=None, parameters=None, trace=(), quantity=None,
                 points: int = 61, figsize=(9.0, 4.0), dpi: int = 80):
        import matplotlib.pyplot as plt

        from .model import Model
        from .plotting import Scene

        widgets = _widgets()
        self.trace, self.quantity, self.points = tuple(trace or ()), quantity, max(int(points), 2)
        self.parameters = dict(parameters or {})
        self.is_model = isinstance(source, Model)
        if not self.is_model and not isinstance(source, Results):
            raise InputError(f"explore needs a spacar.Model or spacar.Results, got {type(source).__name__}")
        if not self.is_model and (self.parameters or input is not None):
            raise InputError("explore: inputs and parameters need a Model (Results only have their output times)")
        self.figure = plt.figure(figsize=figsize, dpi=dpi)
        plt.close(self.figure)  # shown as an image in the widget, not as a figure of its own
        self.message = widgets.Label("")
        self.image = widgets.Image(format="png")
        self.sliders = {}
        self._Scene = Scene
        if self.is_model:
            self.model = source
            self._choose_input(input, input_range)
            name = self.input_name
            lo, hi = self.range
            self.sliders[name] = widgets.FloatSlider(value=lo, min=lo, max=hi, step=(hi - lo) / 200,
                                                     description=name, continuous_update=False,
                                                     readout_format=".4g")
            for pname, spec in self.parameters.items():
                plo, phi, _ = self._parameter(pname, spec)
                value = self._parameter_value(pname, spec)
                self.sliders[pname] = widgets.FloatSlider(value=value, min=plo, max=phi, step=(phi - plo) / 100,
                                                          description=str(pname), continuous_update=False,
                                                          readout_format=".4g")
            self.value = lo
            self._rebuild()
            self.set_input(lo)
        else:
            self.results = source
            n = len(source.t)
            self.sliders["t"] = widgets.IntSlider(value=0, min=0, max=n - 1, description="output",
                                                  continuous_update=False)
            self._draw_results()
            self.set_frame(0)
        for name, slider in self.sliders.items():
            slider.observe(self._on_change(name), names="value")
        self.widget = _static_fallback_box()(list(self.sliders.values()) + [self.message, self.image])
        self.widget.explorer = self

    # --- the model's input and parameters --------------------------------------------------

    def _choose_input(self, input, input_range):
        from . import _core
        from .geometry import family

        sim = _core.Simulation(self.model.copy().core)
        sim.assemble()
        system = sim.system
        inputs = [("x", int(n), int(i)) for (n, i), c in zip(system.coord_label, system.coord_class) if c.name == "input"]
        inputs += [("e", int(n), int(i)) for (n, i), c in zip(system.def_label, system.def_class) if c.name == "input"]
        if input is None:
            if not inputs:
                raise InputError("explore: the model has no input motion (INPUTX, INPUTE) to move")
            input = inputs[0]
        elif isinstance(input, str):
            input = parse_spec(input)
        else:
            input = ("x", *input) if len(input) == 2 else input
        input = (str(input[0]).lower(), int(input[1]), int(input[2]))
        if input not in inputs:
            raise InputError(f"explore: {input[0]}({input[1]},{input[2]}) is not an input motion (INPUTX, INPUTE) of "
                             f"the model; its inputs: {', '.join(f'{q}({n},{i})' for q, n, i in inputs) or 'none'}")
        self.input, self.inputs = input, inputs
        self.input_name = f"{input[0]}({input[1]},{input[2]})"
        q, n, i = input
        if q == "x":
            x0 = float(np.asarray(sim.data.x)[[tuple(lbl) for lbl in system.coord_label].index((n, i))])
            turning = self.model.nodes[n].kind.name == "BETA"
        else:
            x0 = float(np.asarray(sim.data.e)[[tuple(lbl) for lbl in system.def_label].index((n, i))])
            turning = family(self.model.elements[n].type_name) == "Hinge" and i == 1
        if input_range is None:
            input_range = (x0, x0 + 2 * math.pi) if turning else (x0 - 0.5, x0 + 0.5)
        lo, hi = (float(v) for v in input_range)
        if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
            raise InputError(f"explore: input_range must be two finite numbers lo < hi, got {input_range!r}")
        self.range, self.x_assembled = (lo, hi), x0

    def _parameter(self, name, spec):
        """(lo, hi, setter(model, value)) of a parameter: a node coordinate "x(n,i)" (its X
        value: the reference geometry) or any function of the model and the value."""
        try:
            lo, hi, *rest = spec
        except (TypeError, ValueError):
            raise InputError(f"explore: parameter {name!r} needs (lo, hi) or (lo, hi, function(model, value))") from None
        if rest:
            return float(lo), float(hi), rest[0]
        quantity, n, i = parse_spec(name)
        if quantity != "x" or i is None:
            raise InputError(f"explore: parameter {name!r}: name a node coordinate 'x(n,i)' or give "
                             "(lo, hi, function(model, value))")

        def setter(model, value):
            values = list(model.nodes[n].x)
            values[i - 1] = value
            model.x(n, *values)
        return float(lo), float(hi), setter

    def _parameter_value(self, name, spec):
        if len(spec) > 2:
            return (float(spec[0]) + float(spec[1])) / 2
        _, n, i = parse_spec(name)
        return float(self.model.nodes[n].x[i - 1])

    def _model_now(self):
        """A copy of the model with the parameters' slider values, the chosen input moving at
        unit speed from its assembled value and the other inputs held."""
        model = self.model.copy()
        for name, spec in self.parameters.items():
            self._parameter(name, spec)[2](model, self.sliders[name].value)
        for q, n, i in self.inputs:
            (model.xd if q == "x" else model.ed)(n, i, 1.0 if (q, n, i) == self.input else 0.0)
            (model.xdd if q == "x" else model.edd)(n, i, 0.0)
        return model

    def _rebuild(self):
        """Assemble the mechanism with the current parameters, sample the input's range (traces
        and the quantity's curve) and draw."""
        from .plotting import snapshot

        model = self._model_now()
        self._assemble(model)
        self.geometry = Geometry.from_model(model)
        lo, hi = self.range
        rows, values = [], []
        self.note = ""
        for v in np.linspace(lo, hi, self.points):
            if not self._move(v):
                break
            rows.append(snapshot(self.sim, self.geometry))
            values.append(v)
        if not rows:
            raise InputError(f"explore: the mechanism cannot be assembled at {self.input_name} = "
                             f"{lo:g}: {self.message.value}")
        if len(rows) < self.points:
            self.note = (f"{self.input_name} moves from {lo:.4g} to {values[-1]:.4g} only: "
                         f"{self.message.value}")
        self.samples = np.array(values)
        current = rows[0]
        arrays = {name: np.concatenate([getattr(r, name) for r in rows + [current]])
                  for name in _ARRAYS}
        self.states = Results(arrays, current.coordinate_labels, current.deformation_labels, {},
                              geometry=self.geometry)
        self._draw(lambda k: f"{self.input_name} = {self.value:.4g}")

    def _assemble(self, model=None):
        from . import _core

        self.sim = _core.Simulation((model or self._model_now()).core)
        self.sim.assemble()
        self.t0 = float(self.sim.data.t)

    def _move(self, value) -> bool:
        """Solve the kinematics at the input value; False (and a message) where it cannot, and
        the mechanism assembled again (a simulation stuck at a dead position cannot move on)."""
        system = self.sim.system
        try:
            self.sim.move_to(self.t0 + (value - self.x_assembled), system.q0, system.qd0)
        except SpacarError as exc:
            self.message.value = f"{self.input_name} = {value:.4g} not reached: {exc}"
            self._assemble()
            return False
        return True

    def set_input(self, value: float) -> None:
        """Solve the kinematics at the input value and redraw."""
        from .plotting import snapshot

        self.value = float(value)
        if self._move(self.value):
            self.message.value = self.note
            self.state = snapshot(self.sim, self.geometry)
            for name in STATE_ARRAYS:
                getattr(self.states, name)[-1] = getattr(self.state, name)[0]
        self._show(len(self.states.t) - 1, self.value)

    def set_parameter(self, name, value: float) -> None:
        """Set a parameter's slider value: the mechanism is assembled again and redrawn."""
        self.sliders[name].value = value

    # --- drawing ---------------------------------------------------------------------------

    def _draw(self, caption):
        fig = self.figure
        fig.clear()
        source = self.states if self.is_model else self.results
        spatial = source.geometry is not None and source.geometry.spatial
        left = fig.add_subplot(1, 2 if self.quantity else 1, 1, projection="3d" if spatial else None)
        trace = () if self.is_model else self.trace
        self.scene = self._Scene(source, left, 0, trace=trace, caption=caption)
        if self.is_model:
            dim = 3 if spatial else 2
            for n in self.trace:
                if n not in source.node_columns:
                    raise InputError(f"trace: there is no node {n} in the model")
                path = source.x[:-1][:, source.node_columns[n]][:, :dim]
                left.plot(*path.T, color="C3", lw=1.0, alpha=0.6, zorder=2)
        self.curve_ax, self.marker = None, None
        if self.quantity:
            ax = fig.add_subplot(1, 2, 2)
            attr, col = source.column(self.quantity)
            y = getattr(source, attr)[:, col]
            x = self.samples if self.is_model else source.t
            ax.plot(x, y[:-1] if self.is_model else y, color="C0")
            (self.marker,) = ax.plot([x[0]], [y[0]], "o", color="C3")
            ax.set_xlabel(self.input_name if self.is_model else "t [s]")
            ax.set_ylabel(Results.describe(self.quantity))
            ax.grid(True, alpha=0.3)
            self.curve_ax = ax
        fig.tight_layout()

    def _show(self, k, x):
        self.scene.update(k)
        if self.marker is not None:
            source = self.states if self.is_model else self.results
            attr, col = source.column(self.quantity)
            self.marker.set_data([x], [getattr(source, attr)[k, col]])
        buffer = io.BytesIO()
        self.figure.savefig(buffer, format="png")
        self.image.value = buffer.getvalue()

    def _draw_results(self):
        self._draw(None)

    def set_frame(self, k: int) -> None:
        """Draw the results at output index k."""
        self._show(int(k), self.results.t[int(k)])

    def _on_change(self, name):
        def handler(change):
            if not self.is_model:
                self.set_frame(change["new"])
            elif name == self.input_name:
                self.set_input(change["new"])
            else:
                try:
                    self._rebuild()
                except InputError as exc:
                    self.message.value = str(exc)
                    return
                self.set_input(self.value)
        return handler


def explore(source, *, input=None, input_range=None, parameters=None, trace=(), quantity=None, points: int = 61,
            figsize=(9.0, 4.0), dpi: int = 80):
    """An ipywidgets widget to explore a mechanism in a notebook.

    ``source``: a :class:`spacar.Model` — a slider moves the input motion ``input`` (a node
    coordinate ``(n, i)`` with INPUTX, or a label such as ``"e(4,1)"`` for an INPUTE deformation;
    default the model's first) over ``input_range`` (default a full turn from its assembled value
    for a BETA coordinate or a hinge angle, ±0.5 otherwise), solving the
    kinematics at each value; ``parameters`` adds sliders, ``{"x(3,1)": (lo, hi)}`` for a node's X
    coordinate (which sets the reference geometry: link lengths) or ``{name: (lo, hi,
    function(model, value))}``; other inputs stay at their assembled values. Or
    :class:`spacar.Results` — a slider runs through the output times.
    ``trace`` lists nodes whose paths are drawn, ``quantity`` (a label as in :func:`spacar.plot`,
    e.g. ``"x(8,1)"``) is plotted against the input (or time) with a marker at the drawn state.
    Returns the widget (an ``ipywidgets.VBox``; ``widget.explorer`` is the :class:`Explorer`)."""
    return Explorer(source, input=input, input_range=input_range, parameters=parameters, trace=trace,
                    quantity=quantity, points=points, figsize=figsize, dpi=dpi).widget


def view3d(res: Results, k: int = -1, *, beam_points: int = 21, stress=None, stress_kind: str = "normal",
           colorscale: str = "Plasma", mode=None, scale: float | None = None, frames: int = 0, links: bool = True):
    """The mechanism at output index ``k`` as an interactive plotly figure (turn, zoom, hover
    for names), one trace per drawn shape; without plotly the matplotlib drawing of
    :func:`spacar.draw` (a :class:`spacar.plotting.Scene`). ``stress``: the
    :func:`spacar.section.stresses` of these results, drawn as in :func:`spacar.draw`: each of
    its elements in the colour of its largest stress (``stress_kind``), the peak marked.
    ``mode``: a shape in the nodal coordinates (a vibration or buckling mode,
    ``Linearization.mode_shapes()[2][:, i]``) added to that state times ``scale`` (as in
    :func:`spacar.draw`); with ``frames`` ≥ 2 it is animated, times cos(2π j / frames) (the
    still picture, frame 0, at the largest amplitude), with a play button and a slider (the
    animation is kept in the figure's HTML). ``links``: a robot read by :func:`spacar.from_urdf`
    has its links drawn as surfaces too, its URDF <visual> shapes (boxes, cylinders, spheres; meshes
    with trimesh installed, see :mod:`spacar.visuals`)."""
    from .plotting import _displaced, _stress_values, mode_phases
    from .results import require_results

    require_results(res, "view3d")
    if not isinstance(links, (bool, np.bool_)):
        raise InputError(f"view3d: links must be True or False, got {show(links)}")
    if frames != 0 and mode is None:
        raise InputError("frames animate a mode: give mode= too (a shape in the nodal coordinates)")
    phases = mode_phases(frames) if frames != 0 else (1.0,)
    try:
        import plotly.graph_objects as go
    except ImportError:
        from .plotting import draw

        return draw(res, k, beam_points=beam_points, stress=stress, stress_kind=stress_kind, mode=mode, scale=scale)
    if res.geometry is None:
        raise InputError("these results have no geometry to draw (results of spacar.simulate have)")
    k = range(len(res.t))[k]
    values = _stress_values(res, stress, k, stress_kind) if stress is not None else {}
    time = res.t[k]
    rows = [res.x[k]]
    if mode is not None:
        rows = list(_displaced(res, k, mode, scale, phases).x)
    # The scale of the drawing (clamps, triads) from the undisplaced state, the same in every frame.
    coords = frame_coordinates(res.node_columns, res.x[k])
    pts = np.vstack([p for n, p in coords.items() if res.geometry.node_kinds.get(n) in ("XY", "XYZ")])
    size = float(np.ptp(pts, axis=0).max()) or 1.0
    robot = getattr(res, "shapes", None) if links else None
    traces = []
    for x in rows:
        coords = frame_coordinates(res.node_columns, x)
        traces.append(_view3d_traces(go, res.geometry, coords, size, beam_points, values, colorscale, stress_kind)
                      + ([] if robot is None else _link_surfaces(go, robot, coords)))
    fig = _view3d_class(go)(data=traces[0])
    fig.update_layout(scene=dict(aspectmode="data"), title=f"t = {time:.4g} s", margin=dict(l=0, r=0, t=30, b=0))
    if len(traces) > 1:
        for t in traces[1:]:  # a frame moves the vertices; the figure's traces keep the triangles
            for trace in t:
                if trace.type == "mesh3d":
                    trace.i = trace.j = trace.k = None
        fig.frames = [go.Frame(data=t, name=str(j)) for j, t in enumerate(traces)]
        play = dict(frame=dict(duration=1500 // len(traces), redraw=True), fromcurrent=True, mode="immediate")
        fig.update_layout(updatemenus=[dict(type="buttons", showactive=False, x=0.0, y=0.0, buttons=[
            dict(label="play", method="animate", args=[None, {**play, "loop": True}]),
            dict(label="pause", method="animate", args=[[None], dict(mode="immediate", frame=dict(duration=0))])])],
            sliders=[dict(steps=[dict(method="animate", label=str(j), args=[[str(j)], dict(mode="immediate")])
                                 for j in range(len(traces))], x=0.1, len=0.9, currentvalue=dict(prefix="frame "))])
    return fig


_VIEW3D_CLASS = None
_plotly_js_written = False   # whether a figure of this session has carried plotly.js into its HTML


def _view3d_class(go):
    """The class of view3d's figures: a plotly figure whose notebook output carries, beside plotly's
    own mimetype (which JupyterLab draws), its self-contained HTML, which nbconvert and other
    viewers that do not know the mimetype keep (nbconvert drops the figure otherwise). plotly.js
    is written into the first figure displayed in a session only (4.6 MB); ``spacar html``
    writes it into every exported page whatever the outputs hold."""
    global _VIEW3D_CLASS
    if _VIEW3D_CLASS is None:
        class View3D(go.Figure):
            def _ipython_display_(self):   # plotly's displays its renderers' bundle, without the HTML
                global _plotly_js_written
                import plotly.io

                bundle = self._repr_mimebundle_() if plotly.io.renderers.render_on_display else {}
                if "application/vnd.plotly.v1+json" not in bundle:   # no renderer, or an external one
                    return super()._ipython_display_()
                from IPython.display import display

                bundle["text/html"] = plotly.io.to_html(self, include_plotlyjs=not _plotly_js_written,
                                                        full_html=False)
                _plotly_js_written = True
                display(bundle, raw=True)

            def __reduce__(self):   # pickled as a plain plotly figure (this class is made at run time)
                return (go.Figure,) + tuple(super().__reduce__()[1:])
        _VIEW3D_CLASS = View3D
    return _VIEW3D_CLASS


def _link_surfaces(go, robot, coords) -> list:
    """The plotly surfaces of a URDF robot's link shapes at a state ({node: coordinates})."""
    out = []
    for link, role, V, F in robot.surfaces(coords):
        out.append(go.Mesh3d(x=V[:, 0], y=V[:, 1], z=V[:, 2], i=F[:, 0], j=F[:, 1], k=F[:, 2], name=f"link {link}",
                             color="#9ecae1" if role == "visual" else "#c7c7c7", opacity=0.5, flatshading=True,
                             hoverinfo="name", showlegend=False))
    return out


def _view3d_traces(go, geometry, coords, size, beam_points, values, colorscale, stress_kind) -> list:
    """The plotly traces of one state: one per drawn shape, the stress peak, the colour bar."""
    top = max(values.values(), default=0.0) or 1.0
    if values:
        from plotly.colors import sample_colorscale
    colours = {"beam": "#1f77b4", "truss": "#ff7f0e", "body": "#1f77b4", "ground": "#777777", "clamp": "#222222",
               "pin": "#000000", "slider": "#999999", "mass": "#000000", "triad-x": "red", "triad-y": "green",
               "triad-z": "blue", "wheel": "#000000", "belt": "#2ca02c"}
    out = []
    for sh in shapes(geometry, coords, size, beam_points):
        p = np.zeros((len(sh.points), 3))
        p[:, : sh.points.shape[1]] = sh.points
        name = f"{sh.kind} {'element' if sh.element is not None else 'node'} {sh.element if sh.element is not None else sh.node}"
        single = len(p) == 1
        colour = colours.get(sh.kind, "#000000")
        if sh.element in values and not single:
            colour = sample_colorscale(colorscale, [values[sh.element] / top])[0]
            name += f": {values[sh.element]:.4g}"
        out.append(go.Scatter3d(x=p[:, 0], y=p[:, 1], z=p[:, 2], name=name, mode="markers" if single else "lines",
                                line=dict(color=colour, width=6 if sh.kind == "beam" else 3),
                                marker=dict(size=5, color=colour),
                                surfaceaxis=2 if sh.kind == "body" and not geometry.spatial else -1, showlegend=False))
        if values and sh.element == max(values, key=values.get) and not single:
            m = p[len(p) // 2]
            out.append(go.Scatter3d(x=[m[0]], y=[m[1]], z=[m[2]], mode="markers+text", showlegend=False,
                                    marker=dict(size=6, color="red", symbol="diamond"),
                                    text=[f"{values[sh.element]:.3g} (element {sh.element})"], name="peak"))
    if values:  # the colour bar, on an invisible marker
        out.append(go.Scatter3d(x=[None], y=[None], z=[None], mode="markers", showlegend=False, hoverinfo="skip",
                                marker=dict(colorscale=colorscale, cmin=0.0, cmax=top, color=[0.0], showscale=True,
                                            colorbar=dict(title=stress_kind.replace("_", " ") + " stress"))))
    return out
