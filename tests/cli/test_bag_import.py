"""`gryffin-ros import` refuses a bad bag with the reason and writes nothing (no ROS needed: the bags are made here;
a good bag recorded by a planner node is imported in tests/nodes/test_record.py)."""

from __future__ import annotations

import pytest
import yaml

from gryffin_ros.cli import main


def run_import(capsys, *args: str) -> tuple[int, str]:
    code = main(["import", *args])
    return code, capsys.readouterr().err


def metadata(files: list[str]) -> dict:
    return {"rosbag2_bagfile_information": {
        "version": 9, "storage_identifier": "mcap", "relative_file_paths": files, "duration": {"nanoseconds": 0},
        "starting_time": {"nanoseconds_since_epoch": 0}, "message_count": 0, "topics_with_message_count": [],
        "compression_format": "", "compression_mode": "", "files": [], "custom_data": None, "ros_distro": "jazzy"}}


@pytest.mark.parametrize("make, reason", [
    (lambda bag: None, "is not a bag folder"),
    (lambda bag: bag.mkdir(), "has no metadata.yaml: not a rosbag2 bag"),
    (lambda bag: (bag.mkdir(), (bag / "metadata.yaml").write_text("[not, a, mapping")), "cannot read the bag"),
    (lambda bag: (bag.mkdir(), (bag / "metadata.yaml").write_text(yaml.safe_dump(metadata(["bag_0.mcap"]))),
                  (bag / "bag_0.mcap").write_bytes(b"\x89MCAP0\r\n" + b"\0" * 40)), "cannot read the bag"),
    (lambda bag: (bag.mkdir(), (bag / "metadata.yaml").write_text(yaml.safe_dump(metadata([])))),
     "no typed observations of a planner"),
])
def test_a_bad_bag_is_refused_with_the_reason_and_nothing_is_written(tmp_path, capsys, make, reason):
    bag, out = tmp_path / "bag", tmp_path / "out.sqlite"
    make(bag)
    code, err = run_import(capsys, str(bag), "--out", str(out))
    assert code == 2 and reason in err, err
    assert not out.exists()


def test_an_existing_store_is_never_overwritten(tmp_path, capsys):
    out = tmp_path / "campaign.sqlite"
    out.write_bytes(b"kept")
    code, err = run_import(capsys, str(tmp_path), "--out", str(out))
    assert code == 2 and "import writes a new store" in err
    assert out.read_bytes() == b"kept"
