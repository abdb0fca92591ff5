"""The evaluation harness: every method, scripted or learned, scored on the same seeded
episodes (``homing-eval``, ``homing-compare``, ``homing-suite``, ``homing-field``,
``homing-demo``)."""
