"""The collide stage's benchmark (bench/bench_narrow_phase.py) runs on the world's own tables as the step sees
them and reports its counts and timings (no timing is checked): a marble on a height field has its one pair and
its contact, and the same input gives the same contacts bit for bit."""
from bench.bench_narrow_phase import main


def test_a_quick_run_reports_the_marbles_pair_and_contact(capsys):
    first, = main(["--quick", "--scenes", "marble_heightfield", "--no-write"])
    again, = main(["--quick", "--scenes", "marble_heightfield", "--no-write"])
    assert first["pairs"] >= 1 and first["contacts"] >= 1
    assert first["narrow_us"] > 0 and first["aabbs_us"] > 0
    assert first["contacts_digest"] == again["contacts_digest"]
    assert "marble_heightfield" in capsys.readouterr().out
