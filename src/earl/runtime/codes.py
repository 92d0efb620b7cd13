"""The codes of problems found when `earl run` (or `earl.simulate`) binds a spec to its code and data.

`EARL-X…` problems stop a run before its first iteration; each is reported at the spec line that
names the code or the data. docs/runtime.md lists them, and `earl rules X003` explains one; a test
checks that every code the source uses is here and in the page.
"""

from __future__ import annotations

RUNNING_CODES: dict[str, str] = {
    "EARL-X000": 'a partial transition function has no `= python "…"` implementation',
    "EARL-X001": "the implementation is not `module:function` (a dot is no colon)",
    "EARL-X002": "the module cannot be found (modules are looked up next to the spec first)",
    "EARL-X003": "importing the module raised an error, called `sys.exit()`, or imports a module that cannot be found",
    "EARL-X004": "the module has no such function, or it is not callable",
    "EARL-X005": "the function cannot be called with `(inputs, outputs, context)` (or what else it is given), "
    "or is no plain function (a class is only an environment factory)",
    "EARL-X010": "a subsystem's data cannot be set up (e.g. an initial value that does not fit its type)",
    "EARL-X011": "a subsystem has no `fsm`",
    "EARL-X012": "a subsystem has no `period` and a state that waits for nothing",
    "EARL-X013": "a link ends at an input buffer its subsystem does not have",
    "EARL-X014": "a period or timeout below 1 ns, above 10⁹ s, or in an unknown unit (a model built in Python)",
    "EARL-X015": "a subsystem names a state, behaviour, function, predicate, buffer or memory it does not declare, "
    "or starts in no state of its FSM (a model built or edited in Python, run with `check=False`)",
    "EARL-X020": "the environment factory failed (e.g. MuJoCo could not read the model), or the environment's `advance` or `bind` is no method, or its `advance`, `bind` or `close` cannot be called as earl calls it",
    "EARL-X021": "the environment refuses the system (its `bind`): e.g. the MuJoCo model's timestep does not divide a real effector's period, or lacks the actuator a real effector is mapped to",
}
