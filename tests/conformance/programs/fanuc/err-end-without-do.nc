(Rejects END 1 with no open DO 1.)
(items: fanuc.while-do)
(expect-error: fanuc.end-without-do)
O0021
G21 G90 G17
G1 X1 F100
END 1
M30
