"""PNG and EXR files of a frame, written by the library's own writers."""

import numpy as np
import pytest

import alpenglow as ag


def test_png_and_exr_files_are_the_encoders_bytes(renderer, camera, tmp_path):
    out = renderer.render(camera)
    png, exr = tmp_path / "f.png", tmp_path / "f.exr"
    ag.write_png(png, out)
    ag.write_exr(exr, out)
    assert png.read_bytes() == ag.encode_png(out) == ag.encode_png(out["rgba8"])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert exr.read_bytes() == ag.encode_exr(out)
    assert exr.read_bytes()[:4] == bytes([0x76, 0x2F, 0x31, 0x01])
    # Channel names in the header, as the CLI's --exr writes them.
    header = exr.read_bytes()[:4096]
    for name in [b"sun_visibility", b"distance", b"N.X", b"class", b"instance", b"motion.Y", b"Z"]:
        assert name in header


def test_bad_frames_name_the_array(tmp_path):
    with pytest.raises(ValueError, match="rgba8"):
        ag.encode_png(np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="rgba8"):
        ag.encode_png(np.zeros((4, 4, 4), np.float32))
    with pytest.raises(ValueError, match="depth"):
        ag.encode_exr({"hdr": np.zeros((4, 4, 4), np.float32), "depth": np.zeros((4, 5), np.float32)})
    with pytest.raises(ag.Error, match="nowhere"):
        ag.write_png(tmp_path / "nowhere" / "x.png", np.zeros((4, 4, 4), np.uint8))
