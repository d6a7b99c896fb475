"""Generated cells of the deviation register docs/THESIS.md beyond `docs_blocks` (registered
into `tailsim.reports.docs.BLOCKS`).

Source: `docs/reproduction.json` (`missions`: the default and fast missions of both
controllers in both configurations, `analysis reproduction`).
"""

from __future__ import annotations

from .docs import Sources, block

REPRO = "reproduction.json"


def _mission(src: Sources, key: str) -> dict:
    return src.json(REPRO)["missions"][key]


@block("thesis.lqr_cfg1_whole", REPRO)
def _lqr_cfg1_whole(src: Sources) -> str:
    printed, tuned = _mission(src, "lqr_cfg1_default"), _mission(src, "lqr_cfg0_default")
    return (
        f"default mission max position error {printed['max_pos_error']:.2f} m vs tuned {tuned['max_pos_error']:.2f} m "
        f"(`analysis reproduction`, reproduction.json `missions`: {src.json(REPRO)['setting']['plant']})"
    )


@block("thesis.lqr_alpha_max", REPRO)
def _lqr_alpha_max(src: Sources) -> str:
    printed, tuned = _mission(src, "lqr_cfg1_default"), _mission(src, "lqr_cfg0_default")
    return (
        f"default mission max α {printed['alpha_max_deg']:.1f}° → {tuned['alpha_max_deg']:.1f}° "
        f"(`analysis reproduction`, reproduction.json `missions`: {src.json(REPRO)['setting']['plant']})"
    )
