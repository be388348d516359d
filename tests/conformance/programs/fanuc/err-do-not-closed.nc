(Rejects a WHILE [..] DO 1 that is never closed by END 1.)
(items: fanuc.while-do)
(expect-error: fanuc.do-without-end)
O0022
G21 G90 G17
#1 = 0
WHILE [#1 LT 2] DO 1
G1 X#1 F100
#1 = #1 + 1
M30
