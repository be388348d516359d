(Rejects assigning to #0, the Fanuc null variable, which is read-only.)
(items: fanuc.macro-variables)
(expect-error: fanuc.read-only-variable)
O0026
G21 G90 G17
#0 = 1
M30
