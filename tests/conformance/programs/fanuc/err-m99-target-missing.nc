(Rejects M99 P n returning to a sequence number that does not exist in the main program.)
(items: fanuc.m99)
(expect-error: fanuc.goto-target-missing)
O0024
G21 G90 G17
G1 X1 F100
M99 P500
M30
