(Rejects IF [..] followed by neither GOTO nor THEN.)
(items: fanuc.if-goto)
(expect-error: fanuc.if-syntax)
O0025
G21 G90 G17
#1 = 1
IF [#1 EQ 1] G1 X5 F100
M30
