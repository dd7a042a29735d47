"""The page of a replay: its camera, its loop and its overlay (``finish_page``).

A recorded Meshcat scene (``replay.write_replay``, the pick world's ``write_pick_replay``) becomes a
standalone page here: the recording loops (``LOOP_REPETITIONS``), the camera starts at ``CAMERA``
(``with_camera``) and an overlay carries the run's name, the replay's time (``t = … s``, read
from the animation each frame), a pause / play button and a legend of what each colour is
(``overlay_html``).  Nothing here draws the scene: ``replay`` does (and re-exports these names).
"""

from __future__ import annotations

import html as html_text

from pydrake.geometry import Meshcat, MeshcatAnimation, Rgba

# A three-quarter view from the front right (world, z up); meshcat's orbit target stays at the
# world origin, the robot's base.
CAMERA = (0.6, -0.5, 0.45)
_DEFAULT_VIEW = ('viewer.set_property([\'Cameras\', \'default\', \'rotated\', \'<object>\'],\n'
                 '                        "position", [0.0, 1.0, 3.0])')


def with_camera(html: str, camera) -> str:
    """Replace the page's initial camera position (the page sets it after the recorded
    scene loads, so a recorded ``SetCameraPose`` is overridden) by ``camera``.

    ``camera`` is in Drake's z-up world; three.js is y-up: (x, y, z) → (x, z, −y).
    """
    def three(p):
        return f"[{p[0]}, {p[2]}, {-p[1]}]"

    if _DEFAULT_VIEW not in html:
        return html  # another meshcat page layout: keep its own view
    view = (f'viewer.set_property([\'Cameras\', \'default\', \'rotated\', \'<object>\'], '
            f'"position", {three(camera)})')
    return html.replace(_DEFAULT_VIEW, view)


LOOP_REPETITIONS = 1_000_000  # the recording replays this many times (three.js: LoopRepeat)
OVERLAY_ID = "ptint-overlay"
TIME_ID = "ptint-time"


def css_color(rgba: Rgba) -> str:
    """``rgba`` as a CSS colour."""
    return f"rgba({round(255 * rgba.r())}, {round(255 * rgba.g())}, {round(255 * rgba.b())}, {rgba.a():g})"


def overlay_html(title: str, legend: list, note: str = "") -> str:
    """The page's overlay: ``title``, the time display (``TIME_ID``, updated by its script from
    the animation's clip time), a pause / play button and ``legend`` [(CSS colour, text)] as
    swatches; ``note`` under them."""
    rows = "".join(
        f'<div><span style="display:inline-block;width:12px;height:12px;margin-right:6px;'
        f'vertical-align:middle;background:{color};border:1px solid #555"></span>'
        f'{html_text.escape(text)}</div>'
        for color, text in legend)
    extra = f'<div style="margin-top:4px;color:#444">{html_text.escape(note)}</div>' if note else ""
    return (f'<div id="{OVERLAY_ID}" style="position:fixed;left:8px;top:8px;z-index:20;max-width:380px;'
            'background:rgba(255,255,255,0.88);border:1px solid #999;border-radius:4px;padding:6px 8px;'
            'font:13px/1.35 sans-serif;color:#111">'
            f'<div style="font-weight:bold">{html_text.escape(title)}</div>'
            f'<div><span id="{TIME_ID}" style="font:bold 16px monospace">t = 0.00 s</span> '
            '<button id="ptint-play" style="margin-left:8px">pause</button> '
            '<span style="color:#444">(loops)</span></div>'
            f'<div style="margin-top:4px">{rows}</div>{extra}</div>'
            '<script>(function () {'
            f'  var label = document.getElementById("{TIME_ID}");'
            '  var button = document.getElementById("ptint-play");'
            '  button.onclick = function () {'
            '    var a = viewer.animator;'
            '    if (a.playing) { a.pause(); button.textContent = "play"; }'
            '    else { a.play(); button.textContent = "pause"; }'
            '  };'
            '  function tick() {'  # the longest track's time (a track ends at its last key)
            '    var longest = null;'
            '    (viewer.animator ? viewer.animator.actions : []).forEach(function (action) {'
            '      if (!longest || action.getClip().duration > longest.getClip().duration) {'
            '        longest = action;'
            '      }'
            '    });'
            '    if (longest) { label.textContent = "t = " + longest.time.toFixed(2) + " s"; }'
            '    requestAnimationFrame(tick);'
            '  }'
            '  tick();'
            '})();</script>')


def finish_page(meshcat: Meshcat, title: str, legend: list, note: str = "") -> str:
    """Stop the recording, make it loop, publish it and return the standalone page with the
    camera (``CAMERA``) and the overlay (``overlay_html``)."""
    meshcat.StopRecording()
    recording = meshcat.get_mutable_recording()
    recording.set_loop_mode(MeshcatAnimation.LoopMode.kLoopRepeat)
    recording.set_repetitions(LOOP_REPETITIONS)
    recording.set_clamp_when_finished(False)
    meshcat.PublishRecording()
    page = with_camera(meshcat.StaticHtml(), CAMERA)
    return page.replace("</body>", overlay_html(title, legend, note) + "\n</body>", 1)
