%
(Checks a percent-delimited program with an O program number and N sequence numbers.)
(items: fanuc.o-numbers)
(expected: rs274 output of twins/fanuc/program-number.ngc, the same moves written for LinuxCNC)
O0001 (SIMPLE PROFILE)
N10 G21 G90 G17
N20 G0 X0 Y0
N30 G1 X20 F200
N40 Y10
N50 G2 X10 Y20 I-10 J0
N60 G0 X0 Y0
N70 M30
%
