"""What every test of the suite shares."""

import signal

# The tests send Ctrl-C (SIGINT) to earl processes as a terminal would. Started where SIGINT is ignored (a
# background job of a script, as CI may run the suite), pytest's children would inherit the ignore, and earl
# rightly keeps a signal it was started to ignore ignored: a handler here makes every child start with
# SIGINT's default again.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
