"""Test harness of the validation suite: cases, scene writer, engine runners, comparisons,
figures and the error report. Only the tests use it; the marchers do not."""
