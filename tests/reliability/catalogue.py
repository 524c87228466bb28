"""The check every catalogue entry of the reliability tests goes through."""


def check_bad_input(case, ws, cli):
    """Run one catalogue entry ``(name, category, build, code, needles)``: the exit code, one
    or two lines naming every needle, no traceback, no existing file touched and no file
    written (anywhere: in the workspace or beside it)."""
    _name, _category, build, code, needles = case
    argv = build(ws)
    ws.snapshot()
    got, _out, err = cli(argv)
    assert got == code, f"exit {got}, expected {code}\n{err}"
    assert "error:" in err
    body = err.strip().splitlines()
    assert 1 <= len(body) <= 2, f"not one or two lines:\n{err}"
    for needle in needles:
        assert needle in err, f"{needle!r} missing from: {err}"
    ws.check_untouched()
    ws.check_nothing_written()
