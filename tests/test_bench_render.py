"""The renderer's benchmark (bench/bench_render.py) runs a few small frames and reports every part of a frame's
time for every size, in its table and its results file, for the game's renderer and the viewer's (no timing is
checked)."""
import json

from bench.bench_render import PARTS, main


def test_a_few_frames_report_every_part_for_every_size(tmp_path, capsys):
    path = tmp_path / "render.json"
    out = main(["--sizes", "160x90,200x100", "--frames", "3", "--warmup", "1", "--seconds", "1",
                "--json", str(path)])
    assert set(out["results"]) == {"160x90", "200x100"}
    for parts in out["results"].values():
        assert set(parts) == set(PARTS) and all(ms > 0.0 for ms in parts.values())
        assert parts["total"] >= parts["submit"]
    assert {"antialiasing", "shadow_size"} <= set(out["settings"])
    saved = json.loads(path.read_text())
    assert saved["benchmark"] == "render" and saved["results"] == out["results"] and "machine" in saved
    table = capsys.readouterr().out
    assert "160x90" in table and "200x100" in table and "submit" in table


def test_the_viewers_frames_are_timed_alike(capsys):
    out = main(["--viewer", "--sizes", "160x90", "--frames", "3", "--warmup", "1", "--seconds", "0.1"])
    assert out["viewer"] and set(out["results"]) == {"160x90"}
    assert set(out["results"]["160x90"]) == set(PARTS) and out["settings"]["antialiasing"] == "fxaa"
    assert capsys.readouterr().out.startswith("viewer, 3 frames")
