"""The numeric core: the types, the kinematics, the models, the engine, the evaluation and
the uncertainty (numpy only; see ``docs/architecture.md``)."""
