"""A project.json holding an integer of thousands of digits is refused in a person's words,
not Python's advice to call ``sys.set_int_max_str_digits()`` (issue #39). Seen red before:
"project.json is not valid JSON (Exceeds the limit (4300 digits) … sys.set_int_max_str_digits()
…)"."""

from __future__ import annotations

import zipfile

import pytest

from studio.core.files.errors import ProjectError
from studio.core.project.reader import load_project


def test_a_number_of_thousands_of_digits_is_refused_in_plain_words(tmp_path):
    path = tmp_path / "huge.wrinkle"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("project.json", '{"format": "wrinkle-studio", "version": '
                         + "9" * 5000 + "}")
    with pytest.raises(ProjectError) as caught:
        load_project(path)
    message = str(caught.value)
    assert "thousands of digits" in message and "huge.wrinkle" in message
    assert "sys." not in message and "\n" not in message
