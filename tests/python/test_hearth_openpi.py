"""Tests of python/hearth_openpi with numpy alone (python3 -m unittest, or run
this file). Where openpi is importable, the adapter is also compared with
openpi's own LiberoInputs and configs; elsewhere those tests skip.

The expectations about openpi below were written from reading openpi's
source (github.com/Physical-Intelligence/openpi, commit 15a9616):
src/openpi/policies/libero_policy.py, src/openpi/training/config.py,
src/openpi/transforms.py, scripts/serve_policy.py."""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import io
import json
import os
import sys
import tempfile
import types
import unittest

import numpy as np

sys.dont_write_bytecode = True

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "python"))

_openpi_was_loaded = "openpi" in sys.modules
import hearth_openpi  # noqa: E402
from hearth_openpi import config as hconfig  # noqa: E402
from hearth_openpi import policy as hpolicy  # noqa: E402
from hearth_openpi import run as hrun  # noqa: E402


def _openpi_available() -> bool:
    try:
        import openpi.policies.libero_policy  # noqa: F401
        import openpi.training.config  # noqa: F401
    except Exception:
        return False
    return True


HAVE_OPENPI = _openpi_available()


# ---- what openpi's LIBERO transform returns ------------------------------------
# Restated from libero_policy.py (LiberoInputs.__call__ and _parse_image): float
# images are multiplied by 255 and cast to uint8, an image with 3 on its first
# axis is moved from channels-first to channels-last; the output has "state"
# (passed through), "image" with base_0_rgb (front), left_wrist_0_rgb (wrist)
# and right_wrist_0_rgb (zeros shaped like the front image), "image_mask" with
# the same keys, True, True and, for the zero slot, True only for pi0-FAST;
# "actions" and "prompt" copied when present.
def reference_libero_inputs(data: dict, model_type: str) -> dict:
    def parse(im):
        im = np.asarray(im)
        if np.issubdtype(im.dtype, np.floating):
            im = (255 * im).astype(np.uint8)
        if im.shape[0] == 3:
            im = np.moveaxis(im, 0, -1)
        return im

    base = parse(data["observation/image"])
    out = {
        "state": data["observation/state"],
        "image": {
            "base_0_rgb": base,
            "left_wrist_0_rgb": parse(data["observation/wrist_image"]),
            "right_wrist_0_rgb": np.zeros_like(base),
        },
        "image_mask": {
            "base_0_rgb": np.True_,
            "left_wrist_0_rgb": np.True_,
            "right_wrist_0_rgb": np.bool_(model_type == "pi0_fast"),
        },
    }
    if "actions" in data:
        out["actions"] = data["actions"]
    if "prompt" in data:
        out["prompt"] = data["prompt"]
    return out


# openpi.models.model.ModelType, restated: an Enum whose values are these strings
class FakeModelType(enum.Enum):
    PI0 = "pi0"
    PI0_FAST = "pi0_fast"
    PI05 = "pi05"


MODEL_TYPES = ("pi0", "pi0_fast", "pi05")


def eval_observation(thermal: bool = True, size: int = 224) -> dict:
    """What `hearth sim eval` sends (src/eval/eval_run.c, hearth_eval_encode_obs):
    three uint8 (size, size, 3) images, a float64 state of 8, the prompt."""
    rng = np.random.default_rng(7)
    obs = {
        "observation/image": rng.integers(0, 256, (size, size, 3), dtype=np.uint8),
        "observation/wrist_image": rng.integers(0, 256, (size, size, 3), dtype=np.uint8),
        "observation/state": rng.standard_normal(8),
        "prompt": "pick up the iced can and place it on the mat",
    }
    if thermal:
        obs["observation/thermal_image"] = rng.integers(1, 256, (size, size, 3), dtype=np.uint8)
    return obs


def assert_same_leaf(tc: unittest.TestCase, a, b, where: str) -> None:
    a, b = np.asarray(a), np.asarray(b)
    tc.assertEqual(a.dtype, b.dtype, where)
    tc.assertEqual(a.shape, b.shape, where)
    tc.assertTrue(np.array_equal(a, b), where)


def assert_same_structure(tc: unittest.TestCase, got: dict, want: dict, skip=()) -> None:
    tc.assertEqual(set(got), set(want))
    for k in want:
        if isinstance(want[k], dict):
            tc.assertEqual(set(got[k]), set(want[k]), k)
            for s in want[k]:
                if (k, s) in skip:
                    continue
                assert_same_leaf(tc, got[k][s], want[k][s], f"{k}/{s}")
        elif isinstance(want[k], str):
            tc.assertEqual(got[k], want[k], k)
        else:
            assert_same_leaf(tc, got[k], want[k], k)


class TestImport(unittest.TestCase):
    def test_no_openpi_at_import(self):
        if not _openpi_was_loaded and not HAVE_OPENPI:
            self.assertNotIn("openpi", sys.modules)
        self.assertNotIn("hearth_openpi._openpi_build", sys.modules)

    def test_exports(self):
        for name in ("HearthInputs", "HearthOutputs", "server_metadata", "parse_image"):
            self.assertTrue(hasattr(hearth_openpi, name), name)
        self.assertEqual(hearth_openpi.IMAGE_SLOTS, ("base_0_rgb", "left_wrist_0_rgb", "right_wrist_0_rgb"))


class TestInputs(unittest.TestCase):
    def test_rgb_condition_equals_libero(self):
        obs = eval_observation(thermal=True)  # a thermal image present is ignored
        obs["actions"] = np.zeros((10, 7), np.float32)
        for mt in MODEL_TYPES:
            got = hearth_openpi.HearthInputs(model_type=mt, thermal=False)(dict(obs))
            assert_same_structure(self, got, reference_libero_inputs(obs, mt))

    def test_rgb_condition_masks_third_slot(self):
        obs = eval_observation(thermal=True)
        for mt in ("pi0", "pi05"):
            got = hearth_openpi.HearthInputs(model_type=mt, thermal=False)(obs)
            third = got["image"]["right_wrist_0_rgb"]
            self.assertEqual(third.shape, (224, 224, 3))
            self.assertEqual(third.dtype, np.uint8)
            self.assertFalse(third.any())
            self.assertIsInstance(got["image_mask"]["right_wrist_0_rgb"], np.bool_)
            self.assertFalse(got["image_mask"]["right_wrist_0_rgb"])

    def test_thermal_condition(self):
        obs = eval_observation(thermal=True)
        for mt in MODEL_TYPES:
            got = hearth_openpi.HearthInputs(model_type=mt, thermal=True)(obs)
            want = reference_libero_inputs(obs, mt)
            # everything but the third slot as LIBERO's
            assert_same_structure(
                self, got, want, skip={("image", "right_wrist_0_rgb"), ("image_mask", "right_wrist_0_rgb")}
            )
            third = got["image"]["right_wrist_0_rgb"]
            assert_same_leaf(self, third, obs["observation/thermal_image"], "thermal slot")
            self.assertTrue(third.any())
            self.assertIsInstance(got["image_mask"]["right_wrist_0_rgb"], np.bool_)
            self.assertTrue(got["image_mask"]["right_wrist_0_rgb"])

    def test_thermal_missing(self):
        obs = eval_observation(thermal=False)
        with self.assertRaises(KeyError) as cm:
            hearth_openpi.HearthInputs(model_type="pi05")(obs)
        self.assertIn("observation/thermal_image", str(cm.exception))

    def test_thermal_bad_shape(self):
        obs = eval_observation(thermal=True)
        obs["observation/thermal_image"] = np.zeros((224, 224), np.uint8)
        with self.assertRaises(ValueError):
            hearth_openpi.HearthInputs(model_type="pi05")(obs)

    def test_float_chw_like_lerobot(self):
        # LeRobot hands out images as float32 (C, H, W) in [0, 1]
        rng = np.random.default_rng(3)
        chw = {k: rng.random((3, 32, 48), dtype=np.float32) for k in ("f", "w", "t")}
        obs = {
            "observation/image": chw["f"],
            "observation/wrist_image": chw["w"],
            "observation/thermal_image": chw["t"],
            "observation/state": np.zeros(8, np.float32),
            "actions": np.zeros((10, 7), np.float32),
            "prompt": "x",
        }
        got = hearth_openpi.HearthInputs(model_type=FakeModelType.PI05, thermal=True)(obs)
        for slot, k in (("base_0_rgb", "f"), ("left_wrist_0_rgb", "w"), ("right_wrist_0_rgb", "t")):
            want = (255 * chw[k]).astype(np.uint8).transpose(1, 2, 0)
            assert_same_leaf(self, got["image"][slot], want, slot)
            self.assertEqual(got["image"][slot].shape, (32, 48, 3))
        rgb = hearth_openpi.HearthInputs(model_type=FakeModelType.PI05, thermal=False)(obs)
        assert_same_structure(self, rgb, reference_libero_inputs(obs, "pi05"))

    def test_model_type_forms(self):
        obs = eval_observation(thermal=False)
        for mt in (FakeModelType.PI0_FAST, "pi0_fast", "PI0_FAST"):
            got = hearth_openpi.HearthInputs(model_type=mt, thermal=False)(obs)
            self.assertTrue(got["image_mask"]["right_wrist_0_rgb"])
        for bad in ("pi1", 3, None):
            with self.assertRaises(ValueError):
                hearth_openpi.HearthInputs(model_type=bad)

    def test_optional_keys_and_passthrough(self):
        obs = eval_observation(thermal=True)
        del obs["prompt"]
        got = hearth_openpi.HearthInputs(model_type="pi05")(obs)
        self.assertNotIn("prompt", got)
        self.assertNotIn("actions", got)
        self.assertIs(got["state"], obs["observation/state"])

    def test_action_dim_pads(self):
        obs = eval_observation(thermal=True)
        obs["actions"] = np.ones((10, 7), np.float32)
        got = hearth_openpi.HearthInputs(model_type="pi0", action_dim=32)(obs)
        self.assertEqual(got["state"].shape, (32,))
        self.assertEqual(got["actions"].shape, (10, 32))
        self.assertTrue(np.array_equal(got["actions"][:, :7], obs["actions"]))
        self.assertFalse(got["actions"][:, 7:].any())
        self.assertFalse(got["state"][8:].any())

    def test_frozen(self):
        t = hearth_openpi.HearthInputs(model_type="pi05")
        with self.assertRaises(dataclasses.FrozenInstanceError):
            t.thermal = False
        self.assertEqual(t, hearth_openpi.HearthInputs(model_type="pi05", thermal=True))

    def test_example(self):
        ex = hearth_openpi.make_hearth_example(thermal=True)
        got = hearth_openpi.HearthInputs(model_type="pi05")(ex)
        self.assertTrue(got["image_mask"]["right_wrist_0_rgb"])
        self.assertNotIn("observation/thermal_image", hearth_openpi.make_hearth_example(thermal=False))


class TestOutputs(unittest.TestCase):
    def test_slices_to_seven(self):
        a = np.arange(10 * 32, dtype=np.float32).reshape(10, 32)
        got = hearth_openpi.HearthOutputs()({"actions": a, "state": np.zeros(32)})
        self.assertEqual(set(got), {"actions"})
        self.assertEqual(got["actions"].shape, (10, 7))
        self.assertTrue(np.array_equal(got["actions"], a[:, :7]))
        b = np.zeros((4, 10, 32))
        self.assertEqual(hearth_openpi.HearthOutputs()({"actions": b})["actions"].shape, (4, 10, 7))


class TestMetadata(unittest.TestCase):
    def test_server_metadata(self):
        m = hearth_openpi.server_metadata(True)
        self.assertIs(m["hearth_thermal"], True)
        self.assertEqual(
            m["image_keys"], ["observation/image", "observation/wrist_image", "observation/thermal_image"]
        )
        m = hearth_openpi.server_metadata(False)
        self.assertIs(m["hearth_thermal"], False)
        self.assertEqual(m["image_keys"], ["observation/image", "observation/wrist_image"])
        self.assertEqual((m["state_dim"], m["action_dim"]), (8, 7))
        json.dumps(m)  # plain types only: msgpack can carry it


class TestDescribe(unittest.TestCase):
    def test_paper_settings(self):
        for thermal, name in ((True, "pi05_hearth_thermal"), (False, "pi05_hearth_rgb")):
            d = hconfig.describe_train_config(thermal=thermal)
            self.assertEqual(d["name"], name)
            self.assertEqual(d["batch_size"], 512)
            self.assertEqual(d["num_train_steps"], 10_000)
            self.assertEqual(d["seed"], 42)
            self.assertEqual(d["based_on"], "pi05_libero")
            self.assertEqual(d["weight_loader"]["params_path"], "gs://openpi-assets/checkpoints/pi05_libero/params")
            self.assertEqual(
                d["model"], {"class": "Pi0Config", "model_type": "pi05", "pi05": True, "action_horizon": 10,
                             "discrete_state_input": False}
            )
            self.assertTrue(d["data"]["prompt_from_task"])
            self.assertFalse(d["data"]["extra_delta_transform"])
            self.assertEqual(d["data"]["inputs"]["thermal"], thermal)
            self.assertEqual(d["policy_metadata"], hearth_openpi.server_metadata(thermal))
            self.assertEqual(d["data"]["repo_id"], "hearth/sim")
            self.assertEqual(d["data"]["asset_id"], "hearth/sim")
            self.assertIsNone(d["data"]["assets_dir"])

    def test_repack(self):
        r = hconfig.describe_train_config(thermal=True)["data"]["repack"]
        self.assertEqual(
            r,
            {
                "observation/image": "image",
                "observation/wrist_image": "wrist_image",
                "observation/thermal_image": "thermal_image",
                "observation/state": "state",
                "actions": "actions",
                "prompt": "prompt",
            },
        )
        r = hconfig.describe_train_config(thermal=False)["data"]["repack"]
        self.assertNotIn("observation/thermal_image", r)

    def test_arguments(self):
        d = hconfig.describe_train_config("x", False, "me/data", "/tmp/a", batch_size=64, seed=1)
        self.assertEqual((d["name"], d["data"]["repo_id"], d["data"]["assets_dir"]), ("x", "me/data", "/tmp/a"))
        self.assertEqual((d["batch_size"], d["seed"]), (64, 1))
        with self.assertRaises(ValueError):
            hconfig.describe_train_config(repo_id="")
        with self.assertRaises(ValueError):
            hconfig.describe_train_config(batch_size=0)

    def test_cli_json(self):
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            self.assertEqual(hconfig.main([]), 0)
        out = json.loads(buf.getvalue())
        self.assertEqual(set(out), {"pi05_hearth_thermal", "pi05_hearth_rgb"})
        with contextlib.redirect_stderr(io.StringIO()):
            self.assertEqual(hconfig.main(["--bogus"]), 2)

    @unittest.skipIf(HAVE_OPENPI, "openpi is importable here")
    def test_make_needs_openpi(self):
        with self.assertRaises(ImportError) as cm:
            hconfig.make_train_config()
        self.assertIn("openpi", str(cm.exception))


# ---- a stand-in for the parts of openpi that hearth_openpi._openpi_build uses ---
# Shapes restated from openpi's config.py (DataConfigFactory.create_base_config
# fills repo_id / asset_id, asset_id defaulting to repo_id; get_config and cli
# read the module's _CONFIGS_DICT), transforms.py (Group; RepackTransform maps
# new key -> flattened old key) and weight_loaders.py (CheckpointWeightLoader
# holds params_path). Used only where real openpi is missing.
def _fake_openpi() -> dict:
    m_model = types.ModuleType("openpi.models.model")
    m_model.ModelType = FakeModelType
    m_model.BaseModelConfig = object

    m_pi0 = types.ModuleType("openpi.models.pi0_config")

    @dataclasses.dataclass(frozen=True)
    class Pi0Config:
        action_dim: int = 32
        action_horizon: int = 50
        pi05: bool = False
        discrete_state_input: bool | None = None

        @property
        def model_type(self):
            return FakeModelType.PI05 if self.pi05 else FakeModelType.PI0

    m_pi0.Pi0Config = Pi0Config

    m_tr = types.ModuleType("openpi.transforms")

    @dataclasses.dataclass(frozen=True)
    class Group:
        inputs: tuple = ()
        outputs: tuple = ()

    @dataclasses.dataclass(frozen=True)
    class RepackTransform:
        structure: dict

        def __call__(self, data):
            return {new: data[old] for new, old in self.structure.items()}

    m_tr.Group, m_tr.RepackTransform = Group, RepackTransform

    m_wl = types.ModuleType("openpi.training.weight_loaders")

    @dataclasses.dataclass(frozen=True)
    class CheckpointWeightLoader:
        params_path: str

    m_wl.CheckpointWeightLoader = CheckpointWeightLoader

    m_cfg = types.ModuleType("openpi.training.config")

    @dataclasses.dataclass(frozen=True)
    class AssetsConfig:
        assets_dir: str | None = None
        asset_id: str | None = None

    @dataclasses.dataclass(frozen=True)
    class DataConfig:
        repo_id: str | None = None
        asset_id: str | None = None
        repack_transforms: Group = Group()
        data_transforms: Group = Group()
        model_transforms: Group = Group()
        prompt_from_task: bool = False

    @dataclasses.dataclass(frozen=True)
    class DataConfigFactory:
        repo_id: str = "MISSING"
        assets: AssetsConfig = AssetsConfig()
        base_config: DataConfig | None = None

        def create_base_config(self, assets_dirs, model_config):
            return dataclasses.replace(
                self.base_config or DataConfig(), repo_id=self.repo_id, asset_id=self.assets.asset_id or self.repo_id
            )

    @dataclasses.dataclass(frozen=True)
    class ModelTransformFactory:
        def __call__(self, model_config):
            return Group(inputs=("model-transforms",))

    @dataclasses.dataclass(frozen=True)
    class TrainConfig:
        name: str
        model: object = None
        data: object = None
        weight_loader: object = None
        pytorch_weight_path: str | None = None
        batch_size: int = 32
        num_train_steps: int = 30_000
        seed: int = 42
        policy_metadata: dict | None = None
        ema_decay: float | None = 0.99
        exp_name: str = ""

    base = TrainConfig(name="pi05_libero", batch_size=256, ema_decay=0.999, pytorch_weight_path="/path")
    m_cfg.AssetsConfig, m_cfg.DataConfig, m_cfg.DataConfigFactory = AssetsConfig, DataConfig, DataConfigFactory
    m_cfg.ModelTransformFactory, m_cfg.TrainConfig = ModelTransformFactory, TrainConfig
    m_cfg._CONFIGS = [base]
    m_cfg._CONFIGS_DICT = {"pi05_libero": base}
    m_cfg.get_config = lambda name: m_cfg._CONFIGS_DICT[name]

    m_tyro = types.ModuleType("tyro")
    class _Suppress:
        def __class_getitem__(cls, item):
            return item

    m_tyro.conf = types.SimpleNamespace(Suppress=_Suppress)

    mods = {
        "openpi": types.ModuleType("openpi"),
        "openpi.models": types.ModuleType("openpi.models"),
        "openpi.models.model": m_model,
        "openpi.models.pi0_config": m_pi0,
        "openpi.training": types.ModuleType("openpi.training"),
        "openpi.training.config": m_cfg,
        "openpi.training.weight_loaders": m_wl,
        "openpi.transforms": m_tr,
        "tyro": m_tyro,
    }
    return mods


@contextlib.contextmanager
def fake_openpi():
    mods = _fake_openpi()
    saved = {k: sys.modules.get(k) for k in [*mods, "hearth_openpi._openpi_build"]}
    sys.modules.update(mods)
    sys.modules.pop("hearth_openpi._openpi_build", None)
    try:
        yield mods["openpi.training.config"]
    finally:
        for k, v in saved.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v
        if hasattr(hearth_openpi, "_openpi_build"):
            delattr(hearth_openpi, "_openpi_build")


def lerobot_frame(thermal: bool = True) -> dict:
    """One training sample as openpi's LeRobot loader yields it for hearth's
    dataset: float32 CHW images, state (8), an action chunk (10, 7), the
    prompt taken from the frame's task, plus LeRobot's bookkeeping keys."""
    rng = np.random.default_rng(5)
    f = {
        "image": rng.random((3, 224, 224), dtype=np.float32),
        "wrist_image": rng.random((3, 224, 224), dtype=np.float32),
        "state": rng.random(8, dtype=np.float32),
        "actions": rng.random((10, 7), dtype=np.float32),
        "prompt": "pick up the hot cup and place it on the mat",
        "task_index": 0,
        "frame_index": 3,
    }
    if thermal:
        f["thermal_image"] = rng.random((3, 224, 224), dtype=np.float32) * 0.5 + 0.25
    return f


@unittest.skipIf(HAVE_OPENPI, "openpi is importable here: the real-openpi tests run instead")
class TestBuildWithStandIn(unittest.TestCase):
    def test_make_train_config(self):
        with fake_openpi():
            for thermal in (True, False):
                cfg = hconfig.make_train_config(thermal=thermal, exp_name="e")
                self.assertEqual(cfg.name, hconfig.default_name(thermal))
                self.assertEqual((cfg.batch_size, cfg.num_train_steps, cfg.seed), (512, 10_000, 42))
                self.assertEqual(cfg.weight_loader.params_path, "gs://openpi-assets/checkpoints/pi05_libero/params")
                self.assertIsNone(cfg.pytorch_weight_path)
                self.assertEqual(cfg.ema_decay, 0.999)  # kept from pi05_libero
                self.assertEqual(cfg.exp_name, "e")
                self.assertEqual(cfg.model.action_horizon, 10)
                self.assertTrue(cfg.model.pi05)
                self.assertFalse(cfg.model.discrete_state_input)
                self.assertEqual(cfg.policy_metadata, hearth_openpi.server_metadata(thermal))
                dc = cfg.data.create("assets/x", cfg.model)
                self.assertEqual((dc.repo_id, dc.asset_id), ("hearth/sim", "hearth/sim"))
                self.assertTrue(dc.prompt_from_task)
                (inp,) = dc.data_transforms.inputs
                self.assertEqual(inp, hearth_openpi.HearthInputs(model_type=FakeModelType.PI05, thermal=thermal))
                self.assertIsInstance(dc.data_transforms.outputs[0], hearth_openpi.HearthOutputs)
                self.assertEqual(dc.model_transforms.inputs, ("model-transforms",))
                # a LeRobot frame through repack + HearthInputs
                frame = lerobot_frame(thermal=True)
                x = inp(dc.repack_transforms.inputs[0](frame))
                self.assertEqual(set(x), {"state", "image", "image_mask", "actions", "prompt"})
                self.assertEqual(x["image"]["base_0_rgb"].shape, (224, 224, 3))
                self.assertEqual(x["image"]["right_wrist_0_rgb"].any(), thermal)
                self.assertEqual(bool(x["image_mask"]["right_wrist_0_rgb"]), thermal)
                self.assertEqual(x["prompt"], frame["prompt"])

    def test_rgb_config_needs_no_thermal_feature(self):
        with fake_openpi():
            cfg = hconfig.make_train_config(thermal=False)
            dc = cfg.data.create("assets/x", cfg.model)
            x = dc.data_transforms.inputs[0](dc.repack_transforms.inputs[0](lerobot_frame(thermal=False)))
            self.assertFalse(x["image_mask"]["right_wrist_0_rgb"])

    def test_assets_dir(self):
        with fake_openpi():
            cfg = hconfig.make_train_config(repo_id="me/h", assets_dir="/data/lerobot")
            self.assertEqual(cfg.data.assets.assets_dir, "/data/lerobot")
            self.assertEqual(cfg.data.create("a", cfg.model).asset_id, "me/h")

    def test_register(self):
        with fake_openpi() as table, tempfile.TemporaryDirectory() as tmp:
            old = {k: os.environ.pop(k, None) for k in (hconfig.ENV_REPO_ID, hconfig.ENV_ASSETS_DIR)}
            try:
                os.environ[hconfig.ENV_REPO_ID] = "lab/hearth"
                names = hconfig.register()
                self.assertEqual(names, ["pi05_hearth_thermal", "pi05_hearth_rgb"])
                self.assertEqual(table.get_config("pi05_hearth_rgb").data.repo_id, "lab/hearth")
                hconfig.register()  # again: replaces, no duplicates
                self.assertEqual([c.name for c in table._CONFIGS].count("pi05_hearth_thermal"), 1)
                # a foreign config of the same name is not overwritten
                table._CONFIGS_DICT["pi05_hearth_rgb"] = table.TrainConfig(name="pi05_hearth_rgb")
                with self.assertRaises(ValueError):
                    hconfig.register()
                del table._CONFIGS_DICT["pi05_hearth_rgb"]
                # hearth_openpi.run: a script run as __main__ sees the configs
                script = os.path.join(tmp, "probe.py")
                out = os.path.join(tmp, "out.txt")
                with open(script, "w") as f:
                    f.write(
                        "import sys\nimport openpi.training.config as c\n"
                        "if __name__ == '__main__':\n"
                        "    open(sys.argv[1], 'w').write(c.get_config(sys.argv[2]).name)\n"
                    )
                with contextlib.redirect_stderr(io.StringIO()):
                    argv = sys.argv
                    try:
                        self.assertEqual(hrun.main([script, out, "pi05_hearth_rgb"]), 0)
                    finally:
                        sys.argv = argv
                        sys.path.remove(tmp)
                with open(out) as f:
                    self.assertEqual(f.read(), "pi05_hearth_rgb")
            finally:
                for k, v in old.items():
                    os.environ.pop(k, None)
                    if v is not None:
                        os.environ[k] = v


class TestRun(unittest.TestCase):
    def test_usage(self):
        with contextlib.redirect_stderr(io.StringIO()) as err:
            self.assertEqual(hrun.main([]), 2)
            self.assertEqual(hrun.main(["/nonexistent/train.py"]), 2)
        self.assertIn("usage", err.getvalue())


# ---- against openpi itself, where it is installed --------------------------------
@unittest.skipUnless(HAVE_OPENPI, "openpi is not importable (numpy-only environment)")
class TestAgainstOpenpi(unittest.TestCase):
    def test_rgb_equals_libero_inputs(self):
        from openpi.models import model as _model
        from openpi.policies import libero_policy

        obs = eval_observation(thermal=True)
        obs["actions"] = np.zeros((10, 7), np.float32)
        for mt in _model.ModelType:
            want = libero_policy.LiberoInputs(model_type=mt)(dict(obs))
            got = hearth_openpi.HearthInputs(model_type=mt, thermal=False)(dict(obs))
            assert_same_structure(self, got, want)
            got = hearth_openpi.HearthInputs(model_type=mt, thermal=True)(dict(obs))
            assert_same_structure(
                self, got, want, skip={("image", "right_wrist_0_rgb"), ("image_mask", "right_wrist_0_rgb")}
            )
            self.assertTrue(got["image_mask"]["right_wrist_0_rgb"])

    def test_outputs_equal_libero_outputs(self):
        from openpi.policies import libero_policy

        a = np.random.default_rng(1).random((10, 32))
        assert_same_leaf(
            self,
            hearth_openpi.HearthOutputs()({"actions": a})["actions"],
            libero_policy.LiberoOutputs()({"actions": a})["actions"],
            "actions",
        )

    def test_train_config(self):
        import openpi.training.config as _config

        libero = _config.get_config("pi05_libero")
        for thermal in (True, False):
            cfg = hconfig.make_train_config(thermal=thermal)
            self.assertEqual((cfg.batch_size, cfg.num_train_steps, cfg.seed), (512, 10_000, 42))
            self.assertEqual(cfg.model, libero.model)
            self.assertEqual(cfg.lr_schedule, libero.lr_schedule)
            self.assertEqual(cfg.policy_metadata, hearth_openpi.server_metadata(thermal))
        names = hconfig.register()
        for n in names:
            self.assertEqual(_config.get_config(n).name, n)


if __name__ == "__main__":
    unittest.main()
