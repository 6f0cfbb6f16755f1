"""What the studio window remembers and says, without Qt (studio/widgets/window_model.py): the
recent files, where Save As starts, the title and the frame time."""

from __future__ import annotations

import pytest

from studio.widgets.window_model import (
    MAX_RECENT,
    frame_text,
    recent_list,
    save_folder,
    window_title,
    with_recent,
    without_recent,
)

pytestmark = pytest.mark.core


def test_the_file_just_opened_comes_first_once_and_the_list_stays_short():
    files = [f"/work/heads/h{i}.wrinkle" for i in range(MAX_RECENT)]
    again = with_recent(files, files[4])
    assert again[0] == files[4] and again.count(files[4]) == 1 and len(again) == MAX_RECENT
    new = with_recent(files, "/work/heads/new.wrinkle")
    assert new[0] == "/work/heads/new.wrinkle" and files[-1] not in new
    assert without_recent(new, files[0]) == [f for f in new if f != files[0]]


def test_settings_give_a_lone_string_for_a_list_of_one():
    assert recent_list("/a.wrinkle") == ["/a.wrinkle"]
    assert recent_list(None) == [] and recent_list(["/a", "/b"]) == ["/a", "/b"]


def test_save_as_starts_beside_the_project_then_the_characters_mesh(tmp_path):
    mesh = tmp_path / "Characters" / "Ada" / "Ada_neutral.fbx"
    mesh.parent.mkdir(parents=True)
    project = tmp_path / "projects" / "ada.wrinkle"
    assert save_folder(project, str(mesh), False, "/last") == str(project.parent)
    assert save_folder(None, str(mesh), False, "/last") == str(mesh.parent)
    assert save_folder(None, str(mesh), True, "/last") == "/last"  # the bundled sample
    assert save_folder(None, str(tmp_path / "gone" / "x.obj"), False, "/last") == "/last"
    assert save_folder(None, None, False, "/last") == "/last"


def test_title_and_frame_time():
    assert window_title("Ada") == "Ada[*] — Wrinkle Studio"
    assert frame_text(40.0) == "frame 40.0 ms (25 FPS)"
    assert frame_text(0.0).endswith("(1000000 FPS)")  # never a division by zero
