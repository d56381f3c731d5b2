"""The game's benchmark (bench/bench_game.py) plays a little of the course with and without the flag and reports
every part of a step for both runs, in its table and its results file, and replays the steps without the flag
back to back to the same end (no timing is checked)."""
import json

from bench.bench_game import PARTS, main


def test_a_short_play_reports_every_part_with_and_without_the_flag(tmp_path, capsys):
    path = tmp_path / "game.json"
    out = main(["--seconds", "0.25", "--json", str(path)])
    runs = out["results"]
    assert set(runs) == {"flag", "no_flag"}
    for run, r in runs.items():
        assert r["steps"] == 30 and set(PARTS) <= set(r)
        assert r["physics"]["mean_us"] > 0.0 and r["game"]["mean_us"] >= r["physics"]["mean_us"]
        assert (r["push"]["mean_us"] > 0.0) == (run == "flag")
        # the replay of the same steps back to back ends where the play did (else it reports None)
        assert (r["replayed"] is None) == (run == "flag")
    assert runs["no_flag"]["replayed"]["mean_us"] > 0.0
    saved = json.loads(path.read_text())
    assert saved["benchmark"] == "game" and saved["results"] == runs and "machine" in saved
    table = capsys.readouterr().out
    assert "no_flag" in table and "physics" in table
