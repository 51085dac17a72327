"""A hadou PNG sequence as an OpenCue job (docs/farm.md), written with OpenCue's outline library:
one layer whose frames are chunked by OpenCue, each chunk one `hadou render` process. Not run in
CI. Run with `python3 opencue_hadou.py` where pycue and outline are configured for your cuebot."""

from outline import Outline, cuerun
from outline.modules.shell import Shell

SCENE = "/shot/kamehameha.toml"
FRAMES = "/shot/frames/"

job = Outline("hadou-shot-010", frame_range="0-23")
job.add_layer(
    Shell(
        "render",
        # OpenCue replaces #FRAME_START# and #FRAME_END# with the chunk's first and last frame.
        command=[
            "hadou", "render", SCENE, "-o", FRAMES,
            "--frames", "#FRAME_START#..=#FRAME_END#",
            "--width", "1280", "--height", "720", "--samples", "4", "--backend", "cpu",
            "--skip-existing", "--progress", "none",
        ],
        chunk=5,
        range="0-23",
    )
)
cuerun.launch(job, use_pycuerun=False)
