(Checks nested subprograms: O1010 calls O1011 twice; the main program calls O1010 at two places.)
(items: fanuc.m98 fanuc.m99)
(expected: rs274 output of twins/fanuc/m98-nested.ngc, the calls unrolled by hand)
O0005
G21 G90 G17
G0 X0 Y0
M98 P1010
G0 X40 Y0
M98 P1010
M30
O1010 (TWO HOLES 10 MM APART)
M98 P1011
G91 G0 X10
G90
M98 P1011
M99
O1011 (PLUNGE AND RETRACT)
G1 Z-2 F100
G0 Z2
M99
