"""Generated cells of the deviation register docs/THESIS.md beyond `docs_blocks` (registered
into `tailsim.reports.docs.BLOCKS`).

Source: `docs/reproduction.json` (`missions`: the default and fast missions of both
controllers in both configurations, `analysis reproduction`).
"""

from __future__ import annotations

from .docs import Sources, block

REPRO = "reproduction.json"


def _lqr(src: Sources, what: str, text) -> str:
    """`text(printed, tuned)` of the LQR's default mission, configuration 1 against 0, and the
    source."""
    m = src.json(REPRO)["missions"]
    where = f"`analysis reproduction`, reproduction.json `missions`: {src.json(REPRO)['setting']['plant']}"
    return f"default mission {what} {text(m['lqr_cfg1_default'], m['lqr_cfg0_default'])} ({where})"


@block("thesis.lqr_cfg1_whole", REPRO)
def _lqr_cfg1_whole(src: Sources) -> str:
    return _lqr(
        src, "max position error", lambda p, t: f"{p['max_pos_error']:.2f} m vs tuned {t['max_pos_error']:.2f} m"
    )


@block("thesis.lqr_alpha_max", REPRO)
def _lqr_alpha_max(src: Sources) -> str:
    return _lqr(src, "max α", lambda p, t: f"{p['alpha_max_deg']:.1f}° → {t['alpha_max_deg']:.1f}°")
