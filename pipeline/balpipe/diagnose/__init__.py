"""Kinematic trouble explained in the spec's words: structural dyads, dead centres, a loop that
does not close, an assembly branch, actuators that do not drive the mechanism. Each check
locates its error at a spec field."""
