"""Tests for the code-drawn infant face textures."""

import itertools

import numpy as np
import pytest

from mimo_social.expressions.faces import EXPRESSIONS, SKIN_RGB, face_image, face_images

SIZE = 128


def _differing_fraction(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.any(a != b, axis=-1).mean())


def test_expression_names_and_ids():
    assert EXPRESSIONS == ("neutral", "happy", "sad", "surprised", "disgusted", "angry", "scared")
    for i, name in enumerate(EXPRESSIONS):
        np.testing.assert_array_equal(face_image(name, 64), face_image(i, 64))
    np.testing.assert_array_equal(face_image(np.int64(3), 64), face_image("surprised", 64))


@pytest.mark.parametrize("size", [16, 33, 128])
def test_shape_and_dtype(size):
    img = face_image("happy", size)
    assert img.shape == (size, size, 3) and img.dtype == np.uint8
    all_faces = face_images(size)
    assert all_faces.shape == (len(EXPRESSIONS), size, size, 3) and all_faces.dtype == np.uint8


def test_face_images_matches_face_image_and_is_cached_read_only():
    all_faces = face_images(SIZE)
    for i in range(len(EXPRESSIONS)):
        np.testing.assert_array_equal(all_faces[i], face_image(i, SIZE))
    assert face_images(SIZE) is all_faces
    assert not all_faces.flags.writeable
    with pytest.raises(ValueError):
        all_faces[0, 0, 0, 0] = 0
    # face_image hands out a fresh writable array each call
    img = face_image("neutral", SIZE)
    img[:] = 0
    assert face_image("neutral", SIZE).any()


def test_deterministic():
    for name in EXPRESSIONS:
        np.testing.assert_array_equal(face_image(name, 96), face_image(name, 96))


@pytest.mark.parametrize("a,b", list(itertools.combinations(range(len(EXPRESSIONS)), 2)))
def test_every_pair_of_expressions_differs(a, b):
    faces = face_images(SIZE)
    assert _differing_fraction(faces[a], faces[b]) > 0.01, (EXPRESSIONS[a], EXPRESSIONS[b])


@pytest.mark.parametrize("name", EXPRESSIONS)
def test_border_is_plain_skin_and_face_has_features(name):
    img = face_image(name, SIZE)
    frame = SIZE // 10
    border = np.ones((SIZE, SIZE), dtype=bool)
    border[frame:-frame, frame:-frame] = False
    assert np.all(img[border] == np.array(SKIN_RGB, dtype=np.uint8))
    # the centre carries eyes (white sclera), dark pupils and non-skin features
    centre = img[frame:-frame, frame:-frame].reshape(-1, 3).astype(int)
    assert np.any(np.all(centre >= 250, axis=1)), "no white sclera"
    assert np.any(np.all(centre <= 60, axis=1)), "no dark pupil"
    assert np.any(centre != np.array(SKIN_RGB), axis=1).mean() > 0.05


def test_skin_tone():
    r, g, b = SKIN_RGB
    assert r > g > b and r >= 200


@pytest.mark.parametrize("name", ["neutral", "happy", "sad", "surprised", "scared", "angry"])
def test_symmetric_expressions(name):
    img = face_image(name, SIZE)
    assert _differing_fraction(img, img[:, ::-1]) < 0.01


def test_disgust_is_asymmetric():
    img = face_image("disgusted", SIZE)
    assert _differing_fraction(img, img[:, ::-1]) > 0.005


def test_orientation_eyes_above_mouth():
    img = face_image("neutral", SIZE).astype(int)
    white_rows = np.nonzero(np.all(img >= 250, axis=-1).any(axis=1))[0]
    lip_rows = np.nonzero((np.abs(img - [185, 85, 85]).sum(-1) < 10).any(axis=1))[0]
    assert white_rows.size and lip_rows.size
    assert white_rows.max() < lip_rows.min()  # row 0 is the forehead


def test_expressions_have_their_features():
    faces = {n: face_image(n, SIZE).astype(int) for n in EXPRESSIONS}
    lower = slice(SIZE // 2 + SIZE // 8, None)  # the mouth region

    def dark_mouth(n):  # open-mouth interior colour
        return int((np.abs(faces[n][lower] - [150, 45, 60]).sum(-1) < 10).sum())

    for n in ("happy", "surprised", "scared", "disgusted"):
        assert dark_mouth(n) > 0, n
    for n in ("neutral", "sad", "angry"):
        assert dark_mouth(n) == 0, n
    # wide eyes: more sclera in surprised/scared than in neutral
    sclera = {n: int(np.all(f >= 250, axis=-1).sum()) for n, f in faces.items()}
    assert sclera["surprised"] > 1.3 * sclera["neutral"]
    assert sclera["scared"] > 1.3 * sclera["neutral"]
    # surprised mouth is tall and round, scared mouth is wide and flat
    def mouth_box(n):
        rows, cols = np.nonzero(np.abs(faces[n][lower] - [150, 45, 60]).sum(-1) < 10)
        return rows.max() - rows.min() + 1, cols.max() - cols.min() + 1

    h, w = mouth_box("surprised")
    assert h > w
    h, w = mouth_box("scared")
    assert w > 2.5 * h


@pytest.mark.parametrize("bad", ["joy", "Happy", "", -1, 7, 100])
def test_bad_expression_raises_with_allowed_values(bad):
    with pytest.raises(ValueError) as err:
        face_image(bad)
    msg = str(err.value)
    for name in EXPRESSIONS:
        assert name in msg
    assert "0..6" in msg


@pytest.mark.parametrize("bad", [None, 1.5, True])
def test_bad_expression_type_raises(bad):
    with pytest.raises(TypeError, match="neutral"):
        face_image(bad)


@pytest.mark.parametrize("size", [0, 15, 2049, -128])
def test_bad_size_raises_with_allowed_range(size):
    for call in (lambda: face_image("happy", size), lambda: face_images(size)):
        with pytest.raises(ValueError, match=r"\[16, 2048\]"):
            call()


def test_bad_size_type_raises():
    with pytest.raises(TypeError, match="2048"):
        face_image("happy", 64.0)
