"""Hostile values on the command line (issue 13 items 4 and 5, issue 14's typed experiment configs).

Every case runs ``python -m bionav ...`` and expects a non-zero exit, one paragraph that names the
key, the bad value and what is allowed, and no traceback.
"""

from __future__ import annotations

import dataclasses
import typing

import pytest
from helpers import assert_fails_cleanly, run_bionav

from bionav.validation import Range, bounded, check_config, range_of

# (overrides, strings the message must contain)
BAD_VALUES = [
    (["homing.sigma=-1"], ["homing.sigma=-1", "> 0", "default: 1.6"]),
    (["homing.n_features=-5"], ["homing.n_features=-5", "an integer >= 0"]),
    (["homing.sigma=nan"], ["homing.sigma=nan", "NaN"]),
    (["homing.sigma=inf"], ["homing.sigma=inf", "infinite"]),
    (["homing.combine=maximum"], ["homing.combine=maximum", "one of average, max"]),
    (["homing=minwarping", "homing.n_alpha=0"], ["homing.n_alpha=0", ">= 4"]),
    (["homing=minwarping", "homing.image_size=[4,50]"], ["homing.image_size=[4,50]", "a list of 2 items"]),
    (["homing=warping2d", "homing.rho_max=1.5"], ["homing.rho_max=1.5", "< 1"]),
    (["homing=mfdid", "homing.lowpass_sigma=-0.1"], ["homing.lowpass_sigma=-0.1"]),
    (["homing=hiss", "homing.ratio=0"], ["homing.ratio=0", "> 0"]),
    (["homing=parameter", "homing.gradient=steepest"], ["homing.gradient=steepest", "test_steps"]),
    (["homing=parameter", "signature=hist", "signature.bins=1"], ["signature.bins=1", ">= 2"]),
    (["homing=parameter", "signature=mffc_phase", "signature.n_coeffs=0"], ["signature.n_coeffs=0"]),
    (["db.image_size=[100000,20000]"], ["db.image_size=[100000,20000]", "16384"]),
    (["db.noise=-0.5"], ["db.noise=-0.5", ">= 0"]),
    (["db.on_bad_image=ignore"], ["db.on_bad_image=ignore", "error, skip"]),
    (["experiment.step_length=0"], ["experiment.step_length=0", "> 0"]),
    (["experiment.snapshots=[]"], ["experiment.snapshots=[]", "1 to"]),
    (["experiment=cross_db", "experiment.snapshot_stride=0"], ["experiment.snapshot_stride=0"]),
    (["experiment=pol_compass", "experiment.sky.turbidity=-3"], ["experiment.sky.turbidity=-3", ">= 1"]),
    (["experiment=pol_compass", "experiment.solver=magic"], ["experiment.solver=magic", "least_squares"]),
    (["experiment=pol_compass", "sensor.noise_v=-1"], ["sensor.noise_v=-1"]),
    (["experiment=pol_compass", "pantilt.resolution_arcsec=0"], ["pantilt.resolution_arcsec=0"]),
    (["experiment=cleaning", "runs=0"], ["experiment.runs=0", ">= 1"]),
    (["experiment=cleaning", "controller.fix_gain=2"], ["controller.fix_gain=2", "<= 1"]),
    (["experiment=contrast_scan", "experiment.cloud_cover=[0.5,1.5]"], ["experiment.cloud_cover", "1.5"]),
    (["experiment=skyline_homing", "experiment.image_width=0"], ["experiment.image_width=0"]),
    (["experiment=cleaning", "layout.n_lanes=-3"], ["layout.n_lanes=-3", ">= 1"]),
    (["experiment=cleaning", "layout.turn=up"], ["layout.turn=up", "one of left, right"]),
    (["workers=0"], ["workers=0", "an integer >= 1"]),
    (["seed=-1"], ["seed=-1", "an integer >= 0"]),
]


@pytest.mark.slow
@pytest.mark.parametrize("overrides,needles", BAD_VALUES, ids=[" ".join(o) for o, _ in BAD_VALUES])
def test_bad_value_is_named_with_its_range(tmp_path, overrides, needles):
    proc = run_bionav(*overrides, f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "bad value", "allowed", *needles)
    assert proc.returncode == 2
    run = tmp_path / "run"
    assert not run.exists() or not any(run.iterdir())  # refused before anything was run or written


MISSPELT = [
    (["homing.combin=max"], "homing.combin", "Did you mean homing.combine?", "combine, window"),
    (["+homing.combin=max"], "homing.combin", "Did you mean homing.combine?", "window"),
    (["db.image_sise=[150,25]"], "db.image_sise", "Did you mean db.image_size?", "grid_shape"),
    (["db.unfold.sise=[10,2]"], "db.unfold.sise", "Did you mean db.unfold.size?", "outer_radius"),
    (["experiment.step_lenght=1"], "experiment.step_lenght", "Did you mean experiment.step_length?", "success_radius"),
    (["experiment=pol_compass", "experiment.sky.turbiditty=2"], "experiment.sky.turbiditty",
     "Did you mean experiment.sky.turbidity?", "latitude_deg"),
    (["homing=minwarping", "homing.n_alfa=32"], "homing.n_alfa", "Did you mean homing.n_alpha?", "n_psi"),
    (["experiment=cleaning", "layout.n_lane=3"], "layout.n_lane", "Did you mean layout.n_lanes?", "lane_length"),
    (["bionav.resum=true"], "bionav.resum", "Did you mean bionav.resume?", "cache_prepared"),
]


@pytest.mark.slow
@pytest.mark.parametrize("overrides,key,hint,listed", MISSPELT, ids=[" ".join(o) for o, *_ in MISSPELT])
def test_misspelt_key_names_the_node_keys_and_the_closest(tmp_path, overrides, key, hint, listed):
    proc = run_bionav(*overrides, cwd=tmp_path)
    assert_fails_cleanly(proc, f"unknown key {key}", hint, listed, absent=("+homing.", "To append to your config use"))


@pytest.mark.slow
def test_snapshot_index_beyond_the_database_is_named(tmp_path):
    proc = run_bionav("homing=mfdid", "experiment.snapshots=[0,500]", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "experiment.snapshots=[0, 500]", "0..169")


def test_wrong_type_names_key_and_value(tmp_path):
    proc = run_bionav("homing.n_features=abc", cwd=tmp_path)
    assert_fails_cleanly(proc, "homing.n_features=abc", "Integer")


@pytest.mark.slow
def test_memory_bound_refuses_image_stack_before_allocating(tmp_path):
    # inside the per-side range, but 170 images of 16000 x 16000 pixels do not fit in memory
    proc = run_bionav("db.image_size=[16000,16000]", f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, "db.image_size=[16000,16000]", "memory", "choose a smaller db.image_size")


def test_data_node_is_typed():
    from omegaconf import OmegaConf

    from bionav.errors import UserError
    from bionav.experiments.settings import check_group_nodes, experiment_class

    lda = experiment_class("contrast_lda")  # its group_configs type the data= node
    checked = check_group_nodes(OmegaConf.create({"seed": 4, "data": {"name": "sim_natural", "seed": "${seed}",
                                                                       "n_sky": 50}}), lda)
    assert checked["data"].seed == 4 and checked["data"].n_sky == 50
    with pytest.raises(UserError, match=r"data.n_sky=1: .*>= 2"):
        check_group_nodes(OmegaConf.create({"data": {"name": "sim_natural", "n_sky": 1}}), lda)
    with pytest.raises(UserError, match=r"unknown key data.n_skyy.*Did you mean data.n_sky\?"):
        check_group_nodes(OmegaConf.create({"data": {"name": "sim_natural", "n_skyy": 1}}), lda)


# --------------------------------------------------------------------------- the mechanism itself
@dataclasses.dataclass
class _Demo:
    rate: float = bounded(0.5, gt=0.0, le=1.0)
    count: int = bounded(3, ge=1)
    mode: str = bounded("a", choices=("a", "b"))
    size: typing.Optional[list[int]] = bounded(None, length=2, item=Range(ge=8, le=64))
    free: float = 1.0  # no declared range: must still be finite


@pytest.mark.parametrize("field,value,needle", [
    ("rate", 0.0, "> 0"), ("rate", 1.5, "<= 1"), ("rate", float("nan"), "NaN"), ("count", 0, "an integer >= 1"),
    ("mode", "c", "one of a, b"), ("size", [8], "a list of 2 items"), ("size", [8, 65], "65"),
    ("free", float("inf"), "infinite"),
])
def test_check_config_names_key_value_and_range(field, value, needle):
    from bionav.errors import UserError

    cfg = _Demo(**{field: value})
    with pytest.raises(UserError, match=rf"demo\.{field}=") as err:
        check_config(cfg, prefix="demo")
    assert needle in str(err.value) and "allowed" in str(err.value)
    check_config(_Demo(), prefix="demo")  # defaults pass


#: string options that are free text (paths, ports, names resolved elsewhere, times)
#: keys whose values are free text or paths (``calibration``: none | auto | a calibration.json path, checked where
#: the file is read; ``db=bag``'s topic and frame names: checked against the bag where it is read, db/bag/)
FREE_TEXT = {"port", "path", "topic", "signature", "time", "name", "calibration_path", "world", "grid", "route",
             "routes_path", "calibration", "image_topic", "pose_topic", "pose_frame", "world_frame"}


def _all_config_classes():
    from bionav import registry
    from bionav.db.config import DatabaseConfig

    out = [("db", DatabaseConfig)]
    for kind in registry.GROUPS:  # the experiments' Config too (kind experiment) and their group configs
        for name, plugin in registry.plugins_of(kind, warn=False).items():
            if plugin.cls is not None and plugin.entry.distribution == "bionav":
                out.append((f"{kind}={name}", plugin.cls.Config))
                out += [(f"{kind}={name} {node}", schema) for node, schema in
                        dict(getattr(plugin.cls, "group_configs", {})).items()]
    return out


def _fields(cls, prefix=""):
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        hint = hints[f.name]
        if dataclasses.is_dataclass(hint):
            yield from _fields(hint, f"{prefix}{f.name}.")
        else:
            yield f"{prefix}{f.name}", f, hint


def test_every_built_in_value_declares_its_range():
    """Every numeric or enumerated option of every built-in plugin, the db and each experiment has a range."""
    undeclared = []
    for owner, cls in _all_config_classes():
        check_config(cls(), prefix=owner)  # defaults are valid
        for key, f, hint in _fields(cls):
            text = str(hint)
            if hint is bool or "dict" in text or key.split(".")[-1] in FREE_TEXT:
                continue
            if range_of(f) is None and not ("SkyCondition" in text or text == "list[str]"):
                undeclared.append(f"{owner}: {key} ({text})")
    assert not undeclared, "\n".join(undeclared)


# --------------------------------------------------------------------------- keys a database does not use
UNUSED = [
    (["db.grid_shape=[5,5]"], ["db.grid_shape=[5,5] is not used by db=sim_original",
                               "it uses: name, source, image_size, seed"]),
    (["db.spacing_m=0.5"], ["db.spacing_m=0.5 is not used by db=sim_original", "rotation_seed"]),
    (["db=sim_seville", "db.realism=camera"], ["db.realism=camera is not used by db=sim_seville",
                                               "grid_shape, spacing_m, origin_m"]),
    (["db=folder", "db.path=.", "db.seed=3"], ["db.seed=3 is not used by db=folder", "naming, azimuth"]),
    (["experiment=cleaning", "experiment.vision=oracle", "experiment.camera.width=100"],
     ["experiment.camera.width=100 is not used by experiment=cleaning", "oracle"]),
    (["experiment=skyline_homing", "experiment.world=campus", "experiment.grid=[5,5]"],
     ["experiment.grid=[5,5] is not used by experiment=skyline_homing", "world_seed, image_width"]),
    (["db=seville_route", "db.grid_shape=[3,3]"], ["db.grid_shape=[3,3] is not used by db=seville_route",
                                                   "route, routes_path, step_m"]),
]


@pytest.mark.parametrize("overrides,needles", UNUSED, ids=[" ".join(o) for o, _ in UNUSED])
def test_key_a_database_does_not_use_is_an_error(tmp_path, overrides, needles):
    """``db.grid_shape`` on a stand-in with its own grid is refused, naming the keys the database uses (issue 28)."""
    proc = run_bionav(*overrides, f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path)
    assert_fails_cleanly(proc, *needles, "Remove", code=2)
    run = tmp_path / "run"
    assert not run.exists() or not any(run.iterdir())


def test_typed_config_is_the_one_path():
    """Types, declared ranges, per-position ranges, the ``unused_keys`` and ``validate`` hooks, one error style."""
    from omegaconf import OmegaConf

    from bionav.errors import UserError
    from bionav.validation import typed_config

    @dataclasses.dataclass
    class Node:
        lo: float = bounded(1.0, ge=0.0, le=10.0)
        hi: float = bounded(2.0, ge=0.0, le=10.0)
        size: typing.Optional[list[int]] = bounded(None, length=2, items=(Range(ge=8), Range(ge=2)), names=("W", "H"))
        kind: str = bounded("a", choices=("a", "b"))
        only_b: int = bounded(0, ge=0, le=5)

        def unused_keys(self):
            used = ("lo", "hi", "size", "kind") + (("only_b",) if self.kind == "b" else ())
            return [k for k in ("only_b",) if k not in used and self.only_b != 0], used

        def validate(self):
            if not self.lo < self.hi:
                raise UserError(f"node.lo={self.lo} must be below node.hi={self.hi}.")

    got = typed_config(OmegaConf.create({"lo": 1, "size": [8, 2]}), Node, key="node")
    assert isinstance(got, Node) and got.lo == 1.0 and type(got.lo) is float and got.size == [8, 2]
    assert typed_config({"kind": "b", "only_b": 4}, Node, key="node").only_b == 4
    cases = [
        ({"lo": -1}, r"bad value node.lo=-1.0: it is too small; allowed: a finite number >= 0 and <= 10"),
        ({"size": [8, 1]}, r"bad value node.size=\[8,1\]: it has H=1 that is too small; allowed: a list of 2 items, "
                           r"W an integer >= 8, H an integer >= 2"),
        ({"sise": [8, 2]}, r"unknown key node.sise: node \(the node\) has no key 'sise'; its keys are lo, hi, size, "
                           r"kind, only_b. Did you mean node.size\?"),
        ({"lo": "x"}, r"bad value node.lo=x \(the node\): .*Give node.lo a value of the declared type"),
        ({"only_b": 2}, r"node.only_b=2 is not used by the node; it uses: lo, hi, size, kind. Remove node.only_b"),
        ({"lo": 5, "hi": 4}, r"node.lo=5.0 must be below node.hi=4.0"),
    ]
    for node, message in cases:
        with pytest.raises(UserError, match=message):
            typed_config(node, Node, key="node", what="the node")


@pytest.mark.slow
def test_every_db_preset_uses_every_key_it_sets():
    """The presets' own values pass the unused-key check (a stand-in's grid as its preset records it)."""
    from bionav.config import compose, config_options
    from bionav.db.loading import as_database_config

    names = config_options("db")
    assert {"sim_original", "sim_uni", "original", "mesh", "sim_seville", "seville_route"} <= set(names)
    for name in names:
        extra = {"folder": ["db.path=."], "mesh": ["db.world=seville2009"], "bag": ["db.path=robot.bag"]}.get(name, [])
        assert as_database_config(compose([f"db={name}", *extra]).db).name == name
