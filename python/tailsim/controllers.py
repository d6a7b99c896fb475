"""The controller FMUs, found in the declarations: a controller is a unit whose outputs
include every command (the controller interface of
``modelDescription/fragments/controller_interface.json``), so a new controller declared
there appears in the comparison, the campaign and the plots without a change here."""

from . import declarations

#: Model identifiers of the controllers, in declaration order (``tailsitter_<key>``).
MODEL_IDS = tuple(
    m
    for m in declarations.MODELS
    if all(
        c in declarations.VARIABLES[m] and declarations.VARIABLES[m][c].causality == "output"
        for c in declarations.COMMANDS
    )
)
#: Short keys of the controllers (``lqr``, ``tsd``, …): the model identifier without ``tailsitter_``.
KEYS = tuple(m.removeprefix("tailsitter_") for m in MODEL_IDS)
#: Model identifier of each key.
NAMES = dict(zip(KEYS, MODEL_IDS, strict=True))
#: One plot colour per controller, stable across every figure.
COLORS = dict(zip(KEYS, ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown"), strict=False))
