// Yamcs' own SDLS (org.yamcs.security.sdls, in the yamcs-core jar) as a test oracle: reads one
// request a line on stdin, answers one line on stdout. Requests:
//   new NAME KEYHEX SPI WINDOW VERIFY     an AES-256-GCM SA (Yamcs starts its IVs at 0)
//   apply NAME tc SEGHDR FRAMEHEX SECSTART TRAILEREND
//   apply NAME tm SECHDRLEN FRAMEHEX SECSTART TRAILEREND
//   process NAME tc|tm ARG FRAMEHEX SECSTART TRAILEREND
// apply answers the protected frame in hex; process answers "STATUS FRAMEHEX" (the frame with
// its data field decrypted in place). Offsets are from the frame's first octet.
import java.io.BufferedReader;
import java.io.InputStreamReader;
import java.util.HashMap;
import java.util.HexFormat;
import java.util.Map;

import org.yamcs.security.sdls.SdlsSecurityAssociation;
import org.yamcs.security.sdls.SecurityAssociationAes256Gcm128;
import org.yamcs.security.sdls.StandardAuthMask;

public class SdlsOracle {
    public static void main(String[] args) throws Exception {
        HexFormat hex = HexFormat.of();
        Map<String, SdlsSecurityAssociation> sas = new HashMap<>();
        BufferedReader in = new BufferedReader(new InputStreamReader(System.in));
        String line;
        while ((line = in.readLine()) != null) {
            String[] w = line.trim().split(" ");
            try {
                if (w[0].equals("new")) {
                    sas.put(w[1], new SecurityAssociationAes256Gcm128(hex.parseHex(w[2]),
                            (short) Integer.parseInt(w[3]), Integer.parseInt(w[4]),
                            Boolean.parseBoolean(w[5])));
                    System.out.println("ok");
                } else {
                    SdlsSecurityAssociation sa = sas.get(w[1]);
                    byte[] frame = hex.parseHex(w[4]);
                    int secStart = Integer.parseInt(w[5]);
                    int trailerEnd = Integer.parseInt(w[6]);
                    byte[] mask = w[2].equals("tc")
                            ? StandardAuthMask.TC(Boolean.parseBoolean(w[3]), sa.securityHdrAuthMask())
                            : StandardAuthMask.TM(Integer.parseInt(w[3]), sa.securityHdrAuthMask());
                    if (w[0].equals("apply")) {
                        sa.applySecurity(frame, 0, secStart, trailerEnd, mask);
                        System.out.println(hex.formatHex(frame));
                    } else {
                        Object status = sa.processSecurity(frame, 0, secStart, trailerEnd, mask);
                        System.out.println(status + " " + hex.formatHex(frame));
                    }
                }
            } catch (Exception e) {
                System.out.println("error " + e);
            }
            System.out.flush();
        }
    }
}
