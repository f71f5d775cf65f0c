"""Pictures and data sets drawn in-process against the binary's: `mt.render` equals the files
`render --data` writes for the same scene, `mt.generate` writes the binary's pictures byte
for byte, and one renderer serves every call of a process (llvmpipe without a GPU)."""


import numpy as np
import pytest

import marionette as mt
from conftest import ROOT, binary
from marionette import _native

SCENE = ROOT / "assets/default_scene.ron"
SPEC = ROOT / "assets/generate_example.ron"


def test_a_render_is_the_binarys_render_with_data(tmp_path):
    out = mt.render(mt.Scene.load(SCENE), width=160, height=120, data=True)
    binary("render", SCENE, "--width", 160, "--height", 120, "--data", "--out", tmp_path / "shot.png")
    want = _native.read_picture(str(tmp_path / "shot.png"), True)
    assert out["rgb"].dtype == np.uint8 and out["rgb"].shape == (120, 160, 3)
    assert np.array_equal(out["rgb"], want["rgb"])
    assert out["depth"].dtype == np.float32 and out["depth"].shape == (120, 160)
    finite = np.isfinite(want["depth"])
    assert np.array_equal(np.isfinite(out["depth"]), finite) and finite.any()
    assert np.abs(out["depth"][finite] - want["depth"][finite]).max() <= 1e-6
    # Full precision here, a byte a component in the file (n * 0.5 + 0.5, black where nothing).
    assert out["normal"].dtype == np.float32 and out["normal"].shape == (120, 160, 3)
    shown = np.abs(out["normal"]).sum(-1) > 0
    assert np.array_equal(shown, np.abs(want["normal"]).sum(-1) > 0)
    assert np.abs(out["normal"] - want["normal"]).max() <= 1.0 / 255 + 1e-6
    assert np.allclose(np.linalg.norm(out["normal"][shown], axis=-1), 1.0, atol=1e-5)
    assert out["mask"].dtype == np.uint16 and np.array_equal(out["mask"], want["mask"])
    assert out["coco"] == want["coco"]
    # Three puppets, each an instance id of the mask and an annotation with keypoints.
    assert len(out["coco"]["annotations"]) == 3 and len(np.unique(out["mask"])) == 4
    assert out["camera"]["K"].shape == (3, 3) and out["camera"]["world_to_camera"].shape == (4, 4)


def test_the_controlnet_maps_are_the_files_render_writes(tmp_path):
    import json

    out = mt.render(mt.Scene.load(SCENE), width=160, height=120, controlnet=True)
    binary("render", SCENE, "--width", 160, "--height", 120, "--controlnet", "--out", tmp_path / "shot.png")
    maps = out["controlnet"]
    for name in ("openpose", "depth", "normal"):
        want = _native.read_picture(str(tmp_path / f"shot.cn-{name}.png"), False)["rgb"]
        want = want[..., 0] if name == "depth" else want
        assert maps[name].dtype == np.uint8 and np.array_equal(maps[name], want), name
    assert (maps["openpose"] > 0).any() and (maps["depth"] > 0).any()
    assert maps["openpose_json"] == json.loads((tmp_path / "shot.cn-openpose.json").read_text())


def test_the_renderer_is_kept_and_draws_each_scene_alike():
    scene = mt.Scene.load(SCENE)
    first = mt.render(scene, width=160, height=120)["rgb"]
    c = mt.load(ROOT / "tests/data/rigs/mixamo.glb")
    other = mt.render(mt.Scene([c], placements=[(0.0, 0.0, 0.0)]), width=160, height=120, view="front")["rgb"]
    again = mt.render(scene, width=160, height=120)["rgb"]
    assert not np.array_equal(first, other)
    assert np.array_equal(first, again)
    transparent = mt.render(scene, width=160, height=120, transparent=True)["rgb"]
    assert transparent.shape == (120, 160, 4) and (transparent[..., 3] == 0).any()


def test_edges_are_smoothed_as_the_binary_smooths_them(tmp_path):
    scene = mt.Scene.load(SCENE)
    fxaa = mt.render(scene, width=160, height=120, antialias="fxaa")["rgb"]
    binary("render", SCENE, "--width", 160, "--height", 120, "--antialias", "fxaa", "--out", tmp_path / "f.png")
    assert np.array_equal(fxaa, _native.read_picture(str(tmp_path / "f.png"), False)["rgb"])
    assert not np.array_equal(fxaa, mt.render(scene, width=160, height=120)["rgb"])
    with pytest.raises(ValueError, match="antialias: expected multisample, fxaa, off"):
        mt.render(scene, width=160, height=120, antialias="smaa")


def test_generate_writes_the_binarys_pictures_byte_for_byte(tmp_path):
    binary("generate", SPEC, "--out", tmp_path / "cli", "--count", 3)
    samples = list(mt.generate(SPEC, count=3, out=tmp_path / "py"))
    assert [s["key"] for s in samples] == ["000000", "000001", "000002"]
    for s in samples:
        for suffix in (".png", ".json", ".depth.exr", ".mask.png"):
            a = (tmp_path / "py" / f"{s['key']}{suffix}").read_bytes()
            b = (tmp_path / "cli" / f"{s['key']}{suffix}").read_bytes()
            assert a == b, f"{s['key']}{suffix}"
        assert s["rgb"].shape == (240, 320, 3) and s["coco"]["images"][0]["file_name"] == f"{s['key']}.png"


def test_generate_in_memory_gives_the_binarys_pictures_and_data(tmp_path):
    binary("generate", SPEC, "--out", tmp_path / "cli", "--count", 5)
    samples = list(mt.generate(SPEC, count=5, batch=2))
    assert [s["key"] for s in samples] == [f"{k:06}" for k in range(5)]
    for s in samples:
        want = _native.read_picture(str(tmp_path / "cli" / f"{s['key']}.png"), True)
        assert np.array_equal(s["rgb"], want["rgb"]), s["key"]
        assert np.array_equal(s["mask"], want["mask"]) and s["coco"] == want["coco"], s["key"]
        finite = np.isfinite(want["depth"])
        assert np.array_equal(np.isfinite(s["depth"]), finite)
        assert np.abs(s["depth"][finite] - want["depth"][finite]).max() <= 1e-6


def test_a_bad_count_or_batch_is_refused_by_name():
    with pytest.raises(mt.SpecError, match=r"^count: expected 1 to \d+ pictures, found 1000000000000$"):
        next(mt.generate(SPEC, count=10**12))
    with pytest.raises(ValueError, match="batch: expected at least 1 picture, found 0"):
        next(mt.generate(SPEC, count=2, batch=0))


def test_a_shard_and_a_dataset_split_the_set_as_the_binary_does():
    keys = [s["key"] for s in mt.generate(SPEC, shard=(1, 2), count=4)]
    assert keys == ["000001", "000003"]
    ds = mt.Dataset(SPEC, count=2)
    assert len(ds) == 2 and [s["key"] for s in ds] == ["000000", "000001"]


def test_a_bad_spec_is_a_spec_error_with_the_binarys_message(tmp_path):
    bad = tmp_path / "bad.ron"
    bad.write_text(SPEC.read_text().replace("count: 16", "count: -3"))
    with pytest.raises(mt.SpecError) as raised:
        list(mt.generate(bad))
    said = binary("generate", bad, "--out", tmp_path / "set", check=False)
    assert said.returncode != 0 and str(raised.value) in said.stderr
    with pytest.raises(mt.FileError):
        list(mt.generate(tmp_path / "missing.ron"))
    with pytest.raises(ValueError):
        mt.render(mt.Scene.load(SCENE), width=0)
    with pytest.raises(ValueError):
        mt.render(mt.Scene.load(SCENE), view="sideways")
