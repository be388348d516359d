(Rejects GOTO to a sequence number that no block carries.)
(items: fanuc.goto)
(expect-error: fanuc.goto-target-missing)
O0020
G21 G90 G17
G1 X1 F100
GOTO 99
M30
