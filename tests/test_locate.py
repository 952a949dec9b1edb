"""lipjax.data.locate: the paper's data sets are found where users keep them, and only when really there."""
import pytest

from lipjax.data import locate


@pytest.fixture
def places(tmp_path, monkeypatch):
    """Usual places under tmp_path only (the machine's own /data and ~/data stay out of the test)."""
    monkeypatch.chdir(tmp_path)
    for env in locate.ROOT_ENV.values():
        monkeypatch.delenv(env, raising=False)
    monkeypatch.setattr(locate, "USUAL_PLACES", {"nyu": ("data/nyudepthv2", "other/nyu"),
                                                 "kitti": ("data/kitti_depth",)})
    return tmp_path


def test_a_usual_place_counts_only_with_the_loaders_layout(places):
    (places / "data" / "nyudepthv2" / "val").mkdir(parents=True)  # the folder, but no frames
    assert locate.find_data_root("nyu") is None
    (places / "other" / "nyu" / "nyudepthv2" / "val" / "office_0001").mkdir(parents=True)
    (places / "other" / "nyu" / "nyudepthv2" / "val" / "office_0001" / "1.h5").touch()  # the parent layout
    assert locate.find_data_root("nyu") == locate.Path("other/nyu")
    (places / "data" / "nyudepthv2" / "val" / "office_0001").mkdir()
    (places / "data" / "nyudepthv2" / "val" / "office_0001" / "1.h5").touch()
    assert locate.find_data_root("nyu") == locate.Path("data/nyudepthv2")  # the first place wins
    assert locate.find_data_root("kitti") is None
    image = places / "data" / "kitti_depth" / "depth_selection" / "val_selection_cropped" / "image"
    image.mkdir(parents=True)
    assert locate.find_data_root("kitti") is None
    (image / "2011_09_26_drive_0002_sync_image_0000000005_image_02.png").touch()
    assert locate.find_data_root("kitti") == locate.Path("data/kitti_depth")


def test_the_environment_variable_is_used_as_given(places, monkeypatch):
    monkeypatch.setenv("LIPJAX_NYU_DIR", str(places / "mine"))  # empty: the loader, not the search, says so
    assert locate.find_data_root("nyu") == places / "mine"
    assert "$LIPJAX_NYU_DIR" in locate.not_found_note("nyu")
    with pytest.raises(ValueError, match="unknown data set 'tum'"):
        locate.find_data_root("tum")
