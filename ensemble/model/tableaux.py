"""Butcher tableaux of the IMEX additive Runge-Kutta pairs, in exact fractions.

Data, the conversions the kernels need, and what the registry (methods.py) asks of a scheme; the
order conditions are checked in tests/test_ark4.py.
"""
from fractions import Fraction
from typing import NamedTuple

import numpy as np

from .steppers import ark_stepper


class ArkPair(NamedTuple):
    """An IMEX additive Runge-Kutta pair as published, in exact fractions ("p/q" strings).

    Explicit and ESDIRK tableaux share the nodes c and the weights b (the
    implicit one is stiffly accurate: its last row is b); bhat are the embedded
    weights. `explicit[s]` and `implicit[s]` are row s left of the diagonal;
    the implicit diagonal is gamma except for the explicit first stage.
    """
    name: str
    order: int
    embedded_order: int
    c: tuple
    explicit: tuple
    implicit: tuple
    gamma: str
    b: tuple
    bhat: tuple
    kind = "adaptive IMEX"

    def stepper(self):
        """The pair's stepper (steppers.ark_step with its arrays), compiled on first use."""
        return ark_stepper(*self.kernel_arrays())

    def error_weights(self):
        """b - bhat (steppers.block_error)."""
        return self.kernel_arrays()[4]

    def refusal(self, law):
        return None

    def matrices(self):
        """(c, A_E, A_I, b, bhat) as Fractions; A_E and A_I square, A_I with its diagonal."""
        g = Fraction(self.gamma)
        ai = _square(self.implicit)
        for i in range(1, len(ai)):
            ai[i][i] = g
        return (_fractions(self.c), _square(self.explicit), ai, _fractions(self.b),
                _fractions(self.bhat))

    def kernel_arrays(self):
        """What `ark_step` takes: c, A_E, A_I left of the diagonal, b, b - bhat (float arrays), gamma.

        b - bhat is the difference of the rounded weights, so that the error
        estimate is exactly the difference of the two solutions as computed.
        """
        b, bhat = _fractions(self.b), _fractions(self.bhat)
        return (np.array(_fractions(self.c), dtype=float),
                np.array(_square(self.explicit), dtype=float),
                np.array(_square(self.implicit), dtype=float),
                np.array(b, dtype=float),
                np.array([float(p) - float(q) for p, q in zip(b, bhat)]),
                float(Fraction(self.gamma)))


def _fractions(xs):
    return [Fraction(x) for x in xs]


def _square(rows):
    """Strictly lower triangular square matrix (Fractions) from rows left of the diagonal."""
    s = len(rows)
    return [_fractions(row) + [Fraction(0)] * (s - len(row)) for row in rows]


# Kennedy & Carpenter (2003), Appl. Numer. Math. 44, 139, with the coefficients as SUNDIALS
# ARKODE ships them (ARK324L2SA_{ERK,DIRK}_4_2_3, ARK436L2SA_{ERK,DIRK}_6_3_4,
# ARK548L2SA_{ERK,DIRK}_8_4_5). Many are 13-digit rational approximations of irrational
# values; they satisfy the order conditions to about 1e-26, not exactly.
ARK324 = ArkPair(
    "ARK3(2)4L[2]SA", 3, 2,
    c=("0", "1767732205903/2027836641118", "3/5", "1"),
    explicit=((),
              ("1767732205903/2027836641118",),
              ("5535828885825/10492691773637", "788022342437/10882634858940"),
              ("6485989280629/16251701735622", "-4246266847089/9704473918619",
               "10755448449292/10357097424841")),
    implicit=((),
              ("1767732205903/4055673282236",),
              ("2746238789719/10658868560708", "-640167445237/6845629431997"),
              ("1471266399579/7840856788654", "-4482444167858/7529755066697",
               "11266239266428/11593286722821")),
    gamma="1767732205903/4055673282236",
    b=("1471266399579/7840856788654", "-4482444167858/7529755066697",
       "11266239266428/11593286722821", "1767732205903/4055673282236"),
    bhat=("2756255671327/12835298489170", "-10771552573575/22201958757719",
          "9247589265047/10645013368117", "2193209047091/5459859503100"))

ARK436 = ArkPair(
    "ARK4(3)6L[2]SA", 4, 3,
    c=("0", "1/2", "83/250", "31/50", "17/20", "1"),
    explicit=((),
              ("1/2",),
              ("13861/62500", "6889/62500"),
              ("-116923316275/2393684061468", "-2731218467317/15368042101831",
               "9408046702089/11113171139209"),
              ("-451086348788/2902428689909", "-2682348792572/7519795681897",
               "12662868775082/11960479115383", "3355817975965/11060851509271"),
              ("647845179188/3216320057751", "73281519250/8382639484533",
               "552539513391/3454668386233", "3354512671639/8306763924573", "4040/17871")),
    implicit=((),
              ("1/4",),
              ("8611/62500", "-1743/31250"),
              ("5012029/34652500", "-654441/2922500", "174375/388108"),
              ("15267082809/155376265600", "-71443401/120774400", "730878875/902184768",
               "2285395/8070912"),
              ("82889/524892", "0", "15625/83664", "69875/102672", "-2260/8211")),
    gamma="1/4",
    b=("82889/524892", "0", "15625/83664", "69875/102672", "-2260/8211", "1/4"),
    bhat=("4586570599/29645900160", "0", "178811875/945068544", "814220225/1159782912",
          "-3700637/11593932", "61727/225920"))

ARK548 = ArkPair(
    "ARK5(4)8L[2]SA", 5, 4,
    c=("0", "41/100", "2935347310677/11292855782101", "1426016391358/7196633302097", "92/100",
       "24/100", "3/5", "1"),
    explicit=((),
              ("41/100",),
              ("367902744464/2072280473677", "677623207551/8224143866563"),
              ("1268023523408/10340822734521", "0", "1029933939417/13636558850479"),
              ("14463281900351/6315353703477", "0", "66114435211212/5879490589093",
               "-54053170152839/4284798021562"),
              ("14090043504691/34967701212078", "0", "15191511035443/11219624916014",
               "-18461159152457/12425892160975", "-281667163811/9011619295870"),
              ("19230459214898/13134317526959", "0", "21275331358303/2942455364971",
               "-38145345988419/4862620318723", "-1/8", "-1/8"),
              ("-19977161125411/11928030595625", "0", "-40795976796054/6384907823539",
               "177454434618887/12078138498510", "782672205425/8267701900261",
               "-69563011059811/9646580694205", "7356628210526/4942186776405")),
    implicit=((),
              ("41/200",),
              ("41/400", "-567603406766/11931857230679"),
              ("683785636431/9252920307686", "0", "-110385047103/1367015193373"),
              ("3016520224154/10081342136671", "0", "30586259806659/12414158314087",
               "-22760509404356/11113319521817"),
              ("218866479029/1489978393911", "0", "638256894668/5436446318841",
               "-1179710474555/5321154724896", "-60928119172/8023461067671"),
              ("1020004230633/5715676835656", "0", "25762820946817/25263940353407",
               "-2161375909145/9755907335909", "-211217309593/5846859502534",
               "-4269925059573/7827059040749"),
              ("-872700587467/9133579230613", "0", "0", "22348218063261/9555858737531",
               "-1143369518992/8141816002931", "-39379526789629/19018526304540",
               "32727382324388/42900044865799")),
    gamma="41/200",
    b=("-872700587467/9133579230613", "0", "0", "22348218063261/9555858737531",
       "-1143369518992/8141816002931", "-39379526789629/19018526304540",
       "32727382324388/42900044865799", "41/200"),
    bhat=("-975461918565/9796059967033", "0", "0", "78070527104295/32432590147079",
          "-548382580838/3424219808633", "-33438840321285/15594753105479",
          "3629800801594/4656183773603", "4035322873751/18575991585200"))
